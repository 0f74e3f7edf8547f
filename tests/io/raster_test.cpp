#include "io/raster.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <fstream>
#include <iterator>

#include "common/error.hpp"
#include "ensemble/runner.hpp"
#include "io/scene_file.hpp"
#include "test_files.hpp"

namespace talus::io {
namespace {

const std::array<double, 6> kGeo = {600000.0, 5.0, 0.0, 250000.0, 0.0, -5.0};

TEST(ReadRaster, FlipsRowsToCellCentredNodesAndMapsNodata) {
  const auto dir = testing::FreshDir("dem");
  // 3 columns, 2 rows; row 0 is the north.
  testing::WriteGdalRaster(dir / "dem.tif", {{1, 2, 3}, {4, -9999, 6}}, kGeo, 31287, -9999.0);
  const Raster r = ReadRaster((dir / "dem.tif").string(), "terrain.dem");
  EXPECT_EQ(r.grid.nx, 3);
  EXPECT_EQ(r.grid.ny, 2);
  EXPECT_DOUBLE_EQ(r.grid.x0_m, 600002.5);  // centre of the western column
  EXPECT_DOUBLE_EQ(r.grid.y0_m, 249992.5);  // centre of the southern row
  EXPECT_DOUBLE_EQ(r.values[0], 4);         // south-west
  EXPECT_TRUE(std::isnan(r.values[1]));
  EXPECT_DOUBLE_EQ(r.values[3], 1);  // north-west
  EXPECT_NE(r.crs_wkt.find("Austria Lambert"), std::string::npos) << r.crs_wkt;
  EXPECT_EQ(GeoTransformOf(r.grid), kGeo);
}

TEST(ReadRaster, ReadsEsriAsciiGrids) {
  const auto dir = testing::FreshDir("asc");
  testing::WriteText(
      dir / "dem.asc",
      "ncols 3\nnrows 2\nxllcorner 100\nyllcorner 200\ncellsize 2\nNODATA_value -9999\n"
      "1 2 3\n4 5 -9999\n");
  const Raster r = ReadRaster((dir / "dem.asc").string(), "terrain.dem");
  EXPECT_DOUBLE_EQ(r.grid.x0_m, 101);
  EXPECT_DOUBLE_EQ(r.grid.y0_m, 201);
  EXPECT_DOUBLE_EQ(r.values[0], 4);
  EXPECT_TRUE(std::isnan(r.values[2]));
  EXPECT_TRUE(r.crs_wkt.empty());
}

TEST(ReadRaster, BadFilesAreInputErrors) {
  const auto dir = testing::FreshDir("bad");
  try {
    ReadRaster((dir / "missing.tif").string(), "scene.toml:3: terrain.dem");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("scene.toml:3: terrain.dem: file not found"),
              std::string::npos)
        << e.what();
  }
  testing::WriteText(dir / "junk.tif", "not a raster");
  EXPECT_THROW(ReadRaster((dir / "junk.tif").string(), "terrain.dem"), InputError);
  testing::WriteGdalRaster(dir / "rotated.tif", {{1, 2}, {3, 4}}, {0, 1, 0.1, 10, 0, -1}, 0,
                           std::nullopt);
  try {
    ReadRaster((dir / "rotated.tif").string(), "terrain.dem");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("rotated"), std::string::npos) << e.what();
  }
}

// A raster too large for memory (here a 200000 x 200000 VRT over a tiny file) is an input error
// that names the key, not an allocation failure that aborts the program.
TEST(ReadRaster, HugeRasterIsAnInputError) {
  const auto dir = testing::FreshDir("huge");
  testing::WriteGdalRaster(dir / "small.tif", {{1, 2}, {3, 4}}, kGeo, 0, std::nullopt);
  testing::WriteText(dir / "huge.vrt",
                     R"(<VRTDataset rasterXSize="200000" rasterYSize="200000">
  <GeoTransform>600000, 5, 0, 250000, 0, -5</GeoTransform>
  <VRTRasterBand dataType="Float32" band="1">
    <SimpleSource>
      <SourceFilename relativeToVRT="1">small.tif</SourceFilename>
      <SourceBand>1</SourceBand>
    </SimpleSource>
  </VRTRasterBand>
</VRTDataset>)");
  try {
    ReadRaster((dir / "huge.vrt").string(), "scene.toml:2: terrain.dem");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("scene.toml:2: terrain.dem: "), std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("200000 x 200000 cells"), std::string::npos) << e.what();
  }
}

// A raster in another CRS than the target's was reprojected in memory before its size was checked:
// a 500-byte VRT of 21000 x 21000 cells in WGS 84 over a Swiss LV95 DEM took 30 s and 3.4 GB to be
// refused. The size of the reprojected raster is now known without reading a pixel, and the file
// refused at once, naming it and the two CRSs.
TEST(ReadRasterIn, AReprojectionTooLargeIsRefusedBeforeTheWarp) {
  const auto dir = testing::FreshDir("warp_huge");
  testing::WriteText(dir / "ground.vrt",
                     R"(<VRTDataset rasterXSize="21000" rasterYSize="21000">
  <SRS>EPSG:4326</SRS>
  <GeoTransform>7.43, 1e-06, 0, 46.961, 0, -1e-06</GeoTransform>
  <VRTRasterBand dataType="Byte" band="1"><NoDataValue>255</NoDataValue></VRTRasterBand>
</VRTDataset>)");
  const auto t0 = std::chrono::steady_clock::now();
  try {
    ReadRasterIn((dir / "ground.vrt").string(), testing::Wkt(2056), "scene.toml:3: terrain.ground",
                 nullptr);
    FAIL() << "read";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_EQ(
        what.rfind(
            "scene.toml:3: terrain.ground: " + (dir / "ground.vrt").string() + " would have ", 0),
        0u)
        << what;
    EXPECT_NE(what.find("cells once reprojected from EPSG:4326"), std::string::npos) << what;
    EXPECT_NE(what.find("to EPSG:2056"), std::string::npos) << what;
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_LT(seconds, 10.0);  // the outline only; the warp took 30 s
  // A small raster in another CRS is still reprojected and read.
  testing::WriteText(dir / "small.vrt",
                     R"(<VRTDataset rasterXSize="20" rasterYSize="20">
  <SRS>EPSG:4326</SRS>
  <GeoTransform>7.43, 1e-04, 0, 46.961, 0, -1e-04</GeoTransform>
  <VRTRasterBand dataType="Byte" band="1"><NoDataValue>255</NoDataValue></VRTRasterBand>
</VRTDataset>)");
  std::string from;
  const Raster small =
      ReadRasterIn((dir / "small.vrt").string(), testing::Wkt(2056), "terrain.ground", &from);
  EXPECT_GT(small.grid.nx, 10);
  EXPECT_FALSE(from.empty());
}

TEST(WriteGeoTiff, RoundTripsGridCrsAndValues) {
  const auto dir = testing::FreshDir("write");
  const GridGeometry grid{4, 3, 10.5, 20.5, 1.0, 1.0};
  std::vector<float> values(12);
  for (int k = 0; k < 12; ++k) values[k] = static_cast<float>(k);
  values[5] = -9999.0f;
  WriteGeoTiff((dir / "out.tif").string(), grid, testing::Wkt(31287), values, true, -9999.0,
               {"test"});
  const Raster r = ReadRaster((dir / "out.tif").string(), "out");
  EXPECT_DOUBLE_EQ(r.grid.x0_m, grid.x0_m);
  EXPECT_DOUBLE_EQ(r.grid.y0_m, grid.y0_m);
  EXPECT_EQ(r.grid.nx, 4);
  EXPECT_TRUE(std::isnan(r.values[5]));
  EXPECT_DOUBLE_EQ(r.values[7], 7);
  EXPECT_NE(r.crs_wkt.find("Austria Lambert"), std::string::npos);
  // Complete or absent: no temporary file is left behind.
  int files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir))
    files += entry.is_regular_file();
  EXPECT_EQ(files, 1);
}

std::string Bytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

// The band's description and unit and the dataset's metadata items are written, and the same
// arguments give the same bytes.
TEST(WriteGeoTiff, BandDescriptionUnitAndMetadataItems) {
  const auto dir = testing::FreshDir("metadata");
  const GridGeometry grid{4, 3, 10.5, 20.5, 1.0, 1.0};
  const std::vector<float> values(12, 2.5f);
  const RasterMetadata metadata{"energy, 95th percentile over passing rocks",
                                "J",
                                {{"TALUS_QUANTITY", "energy"}, {"TALUS_GROUND", R"({"a":1})"}}};
  for (const char* name : {"a.tif", "b.tif"})
    WriteGeoTiff((dir / name).string(), grid, testing::Wkt(31287), values, true, -9999.0, metadata);
  EXPECT_TRUE(Bytes(dir / "a.tif") == Bytes(dir / "b.tif"));
  GDALDataset* d =
      static_cast<GDALDataset*>(GDALOpen((dir / "a.tif").string().c_str(), GA_ReadOnly));
  ASSERT_NE(d, nullptr);
  GDALRasterBand* band = d->GetRasterBand(1);
  EXPECT_STREQ(band->GetDescription(), "energy, 95th percentile over passing rocks");
  EXPECT_STREQ(band->GetUnitType(), "J");
  int has_nodata = 0;
  EXPECT_EQ(band->GetNoDataValue(&has_nodata), -9999.0);
  EXPECT_TRUE(has_nodata);
  EXPECT_STREQ(d->GetMetadataItem("TALUS_QUANTITY"), "energy");
  EXPECT_STREQ(d->GetMetadataItem("TALUS_GROUND"), R"({"a":1})");
  EXPECT_EQ(d->GetMetadataItem("LAYOUT", "IMAGE_STRUCTURE"), nullptr);  // a plain GeoTIFF
  GDALClose(d);
}

// A Cloud-Optimised GeoTIFF: GDAL reports LAYOUT=COG and DEFLATE, a raster larger than a tile
// (512 cells) has overviews down to one tile, values, nodata, CRS and metadata are those given,
// and the same arguments give the same bytes.
TEST(WriteGeoTiff, CogHasTheCogLayoutOverviewsAndTheValues) {
  const auto dir = testing::FreshDir("cog");
  const GridGeometry grid{1300, 700, 600002.5, 249002.5, 5.0, 5.0};
  std::vector<float> values(static_cast<std::size_t>(grid.nx) * grid.ny);
  for (std::size_t c = 0; c < values.size(); ++c)
    values[c] = c % 7 == 0 ? -9999.0f : static_cast<float>(c % 1000) * 0.5f;
  const RasterMetadata metadata{"speed, largest over passing rocks", "m/s", {{"TALUS_SEED", "7"}}};
  for (const char* name : {"a.tif", "b.tif"})
    WriteGeoTiff((dir / name).string(), grid, testing::Wkt(31287), values, true, -9999.0, metadata,
                 RasterFormat::kCog);
  EXPECT_TRUE(Bytes(dir / "a.tif") == Bytes(dir / "b.tif"));
  int files = 0;  // no temporary file (nor overview file) is left behind
  for (const auto& entry : std::filesystem::directory_iterator(dir))
    files += entry.is_regular_file();
  EXPECT_EQ(files, 2);

  GDALDataset* d =
      static_cast<GDALDataset*>(GDALOpen((dir / "a.tif").string().c_str(), GA_ReadOnly));
  ASSERT_NE(d, nullptr);
  ASSERT_NE(d->GetMetadataItem("LAYOUT", "IMAGE_STRUCTURE"), nullptr);
  EXPECT_STREQ(d->GetMetadataItem("LAYOUT", "IMAGE_STRUCTURE"), "COG");
  EXPECT_STREQ(d->GetMetadataItem("COMPRESSION", "IMAGE_STRUCTURE"), "DEFLATE");
  GDALRasterBand* band = d->GetRasterBand(1);
  EXPECT_EQ(band->GetOverviewCount(), 2);  // 650 x 350, 325 x 175: the last within one tile
  int block_x = 0, block_y = 0;
  band->GetBlockSize(&block_x, &block_y);
  EXPECT_EQ(block_x, 512);
  EXPECT_EQ(block_y, 512);
  EXPECT_STREQ(band->GetDescription(), "speed, largest over passing rocks");
  EXPECT_STREQ(band->GetUnitType(), "m/s");
  EXPECT_STREQ(d->GetMetadataItem("TALUS_SEED"), "7");
  EXPECT_STREQ(d->GetSpatialRef()->GetAuthorityCode(nullptr), "31287");
  GDALClose(d);
  const Raster r = ReadRaster((dir / "a.tif").string(), "cog");
  EXPECT_DOUBLE_EQ(r.grid.x0_m, grid.x0_m);
  EXPECT_DOUBLE_EQ(r.grid.y0_m, grid.y0_m);
  ASSERT_EQ(r.values.size(), values.size());
  std::size_t same = 0;
  for (std::size_t c = 0; c < values.size(); ++c)
    same += values[c] == -9999.0f ? std::isnan(r.values[c]) : r.values[c] == values[c];
  EXPECT_EQ(same, values.size());

  // A raster within one tile needs no overview, and is still a COG.
  WriteGeoTiff((dir / "small.tif").string(), {10, 8, 0.5, 0.5, 1, 1}, "",
               std::vector<float>(80, 1.0f), true, -9999.0, metadata, RasterFormat::kCog);
  d = static_cast<GDALDataset*>(GDALOpen((dir / "small.tif").string().c_str(), GA_ReadOnly));
  ASSERT_NE(d, nullptr);
  EXPECT_STREQ(d->GetMetadataItem("LAYOUT", "IMAGE_STRUCTURE"), "COG");
  EXPECT_EQ(d->GetRasterBand(1)->GetOverviewCount(), 0);
  GDALClose(d);
}

// End to end on a georeferenced DEM: a rock set down at rest in one DEM cell shows up as a
// deposit in the same row and column of the output GeoTIFF, which carries the DEM's geotransform
// and CRS.
TEST(WriteGeoTiff, OutputCellLinesUpWithTheDemCell) {
  const auto dir = testing::FreshDir("align");
  std::vector<std::vector<double>> rows(
      7, std::vector<double>(9, 1000.0));  // flat, 9 x 7 cells of 5 m
  testing::WriteGdalRaster(dir / "dem.tif", rows, kGeo, 31287, -9999.0);
  // Release in GDAL column 6, row 2: x in [600030, 600035), y in (249985, 249990].
  const double x = 600031.0, y = 249986.5;
  testing::WriteText(
      dir / "scene.toml",
      "[terrain]\ndem = \"dem.tif\"\n[rock]\nshape = { box = [0.4, 0.4, 0.4] }\n"
      "[release]\npoints = [[600031.0, 249986.5]]\nheight_m = 0.2\norientation = [1, 0, 0, 0]\n"
      "rocks = 2\n[solver]\nmax_time_s = 5\n[output]\nrasters = [\"deposits\"]\n");
  const SceneFile scene = LoadScene((dir / "scene.toml").string());
  ensemble::EnsembleOptions options;
  options.rasters = scene.output.Request(scene.scene.terrain.heights().grid);
  const ensemble::EnsembleReport report =
      ensemble::RunEnsemble(scene.scene, scene.release, options);
  ASSERT_EQ(report.count(EndReason::kRest), 2);
  ASSERT_EQ(report.rasters.size(), 1u);
  const auto out = (dir / "deposits.tif").string();
  WriteGeoTiff(out, scene.scene.terrain.heights().grid, scene.crs_wkt, report.rasters[0].values,
               false, 0, {"deposits"});

  RegisterGdal();
  GDALDataset* d = static_cast<GDALDataset*>(GDALOpen(out.c_str(), GA_ReadOnly));
  ASSERT_NE(d, nullptr);
  double gt[6];
  d->GetGeoTransform(gt);
  for (int k = 0; k < 6; ++k) EXPECT_DOUBLE_EQ(gt[k], kGeo[k]) << k;
  GDALDataset* dem = static_cast<GDALDataset*>(GDALOpen((dir / "dem.tif").c_str(), GA_ReadOnly));
  EXPECT_TRUE(d->GetSpatialRef()->IsSame(dem->GetSpatialRef()));
  EXPECT_STREQ(d->GetSpatialRef()->GetAuthorityCode(nullptr), "31287");
  GDALClose(dem);
  std::vector<float> pixels(63);
  ASSERT_EQ(
      d->GetRasterBand(1)->RasterIO(GF_Read, 0, 0, 9, 7, pixels.data(), 9, 7, GDT_Float32, 0, 0),
      CE_None);
  GDALClose(d);
  const int column = static_cast<int>((x - kGeo[0]) / kGeo[1]);
  const int row = static_cast<int>((y - kGeo[3]) / kGeo[5]);
  ASSERT_EQ(column, 6);
  ASSERT_EQ(row, 2);
  for (int r = 0; r < 7; ++r)
    for (int c = 0; c < 9; ++c)
      EXPECT_EQ(pixels[r * 9 + c], (r == row && c == column) ? 2.0f : 0.0f) << r << "," << c;
}

TEST(IsGeographicCrs, TellsDegreesFromMetres) {
  EXPECT_TRUE(IsGeographicCrs(testing::Wkt(4326)));    // WGS 84
  EXPECT_TRUE(IsGeographicCrs(testing::Wkt(4258)));    // ETRS89
  EXPECT_FALSE(IsGeographicCrs(testing::Wkt(31287)));  // MGI / Austria Lambert
  EXPECT_FALSE(IsGeographicCrs(testing::Wkt(32632)));  // WGS 84 / UTM 32N
  EXPECT_FALSE(IsGeographicCrs(""));
}

TEST(DescribeCrs, NamesCodeAndName) {
  EXPECT_EQ(DescribeCrs(testing::Wkt(31287)), "EPSG:31287 (MGI / Austria Lambert)");
  EXPECT_EQ(DescribeCrs(testing::Wkt(4326)), "EPSG:4326 (WGS 84)");
  EXPECT_EQ(DescribeCrs(""), "no CRS");
}

TEST(UtmEpsgFor, ZoneAndHemisphereOfThePoint) {
  EXPECT_EQ(UtmEpsgFor(11.0, 47.0), "EPSG:32632");
  EXPECT_EQ(UtmEpsgFor(-70.6, -33.4), "EPSG:32719");
  EXPECT_EQ(UtmEpsgFor(-180.0, 0.0), "EPSG:32601");
  EXPECT_EQ(UtmEpsgFor(180.0, 0.0), "EPSG:32660");
  EXPECT_EQ(UtmEpsgFor(11.0, 88.0), "");      // polar: no UTM zone
  EXPECT_EQ(UtmEpsgFor(600000, 250000), "");  // metres, not degrees
}

}  // namespace
}  // namespace talus::io
