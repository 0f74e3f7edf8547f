#include "io/vector.hpp"

#include <gdal_priv.h>
#include <gtest/gtest.h>
#include <ogrsf_frmts.h>

#include <memory>

#include "common/error.hpp"
#include "io/scene_file.hpp"
#include "test_files.hpp"

namespace talus::io {
namespace {

using Kind = ensemble::ReleaseGeometry::Kind;

const char* kGeoJson = R"({"type": "FeatureCollection", "features": [
 {"type": "Feature", "properties": {}, "geometry": {"type": "Point", "coordinates": [5, 1]}},
 {"type": "Feature", "properties": {}, "geometry": {"type": "LineString", "coordinates": [[2, -3], [2, 3]]}},
 {"type": "Feature", "properties": {}, "geometry": {"type": "MultiPolygon", "coordinates":
   [[[[8, -2], [10, -2], [10, 2], [8, 2], [8, -2]]], [[[12, -1], [13, -1], [13, 1], [12, -1]]]]}}
]})";

TEST(ReadReleaseGeometries, GeoJsonPointsLinesAndMultiPolygons) {
  const auto dir = testing::FreshDir("geojson");
  testing::WriteText(dir / "release.geojson", kGeoJson);
  const auto g = ReadReleaseGeometries((dir / "release.geojson").string(), "", "release.file");
  ASSERT_EQ(g.size(), 4u);
  EXPECT_EQ(g[0].kind, Kind::kPoint);
  EXPECT_EQ(g[0].rings[0][0], Eigen::Vector2d(5, 1));
  EXPECT_EQ(g[1].kind, Kind::kLine);
  EXPECT_EQ(g[2].kind, Kind::kPolygon);
  EXPECT_EQ(g[2].rings[0].size(), 4u);  // closing point dropped
  EXPECT_EQ(g[3].kind, Kind::kPolygon);
}

TEST(ReadReleaseGeometries, SceneReleaseFileIsRelativeToTheScene) {
  const auto dir = testing::FreshDir("scene");
  std::filesystem::create_directories(dir / "gis");
  testing::WriteText(dir / "gis" / "release.geojson", kGeoJson);
  testing::WriteText(
      dir / "scene.toml",
      "[terrain]\nplane = { slope_deg = 30, slope_length_m = 20, runout_m = 10, width_m = 20 }\n"
      "[rock]\nshape = { box = [1, 1, 1] }\n[release]\nfile = \"gis/release.geojson\"\nrocks = "
      "3\n");
  const SceneFile s = LoadScene((dir / "scene.toml").string());
  EXPECT_EQ(s.release.releases.size(), 4u);
  EXPECT_EQ(s.release.total_rocks(), 12);
}

TEST(ReadReleaseGeometries, BadFiles) {
  const auto dir = testing::FreshDir("bad");
  EXPECT_THROW(ReadReleaseGeometries((dir / "none.geojson").string(), "", "release.file"),
               InputError);
  testing::WriteText(dir / "empty.geojson", R"({"type": "FeatureCollection", "features": []})");
  try {
    ReadReleaseGeometries((dir / "empty.geojson").string(), "", "release.file");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("has no point, line or polygon"), std::string::npos)
        << e.what();
  }
  // A release in a CRS while the DEM has none cannot be placed.
  testing::WriteText(
      dir / "crs.geojson",
      R"({"type": "FeatureCollection", "crs": {"type": "name", "properties": {"name": "urn:ogc:def:crs:EPSG::31287"}},
 "features": [{"type": "Feature", "properties": {}, "geometry": {"type": "Point", "coordinates": [5, 1]}}]})");
  try {
    ReadReleaseGeometries((dir / "crs.geojson").string(), "", "release.file");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("the DEM has none"), std::string::npos) << e.what();
  }
}

TEST(ReadReleaseGeometries, ReprojectsToTheDemCrs) {
  const auto dir = testing::FreshDir("reproject");
  // A point given in WGS 84 lon/lat; the DEM is in MGI / Austria Lambert (EPSG:31287).
  testing::WriteText(
      dir / "wgs84.geojson",
      R"({"type": "FeatureCollection", "features": [{"type": "Feature", "properties": {},
 "geometry": {"type": "Point", "coordinates": [11.4, 47.3]}}]})");
  const auto g =
      ReadReleaseGeometries((dir / "wgs84.geojson").string(), testing::Wkt(31287), "release.file");
  ASSERT_EQ(g.size(), 1u);
  // Innsbruck area in Austria Lambert: x about 250 km, y about 370 km (false origin 400 km, 400
  // km).
  EXPECT_GT(g[0].rings[0][0].x(), 200000);
  EXPECT_LT(g[0].rings[0][0].x(), 300000);
  EXPECT_GT(g[0].rings[0][0].y(), 330000);
  EXPECT_LT(g[0].rings[0][0].y(), 400000);
}

// A GeoPackage of two layers in EPSG:31287: "zones" (polygons with a text field zone and an
// integer field active) and "blocks" (points).
void WriteTwoLayerGeoPackage(const std::filesystem::path& path) {
  RegisterGdal();
  GDALDriver* driver = GetGDALDriverManager()->GetDriverByName("GPKG");
  ASSERT_NE(driver, nullptr);
  std::unique_ptr<GDALDataset> d(driver->Create(path.c_str(), 0, 0, 0, GDT_Unknown, nullptr));
  ASSERT_NE(d, nullptr);
  OGRSpatialReference srs;
  srs.importFromEPSG(31287);
  OGRLayer* zones = d->CreateLayer("zones", &srs, wkbPolygon, nullptr);
  OGRFieldDefn zone("zone", OFTString);
  OGRFieldDefn active("active", OFTInteger);
  ASSERT_EQ(zones->CreateField(&zone), OGRERR_NONE);
  ASSERT_EQ(zones->CreateField(&active), OGRERR_NONE);
  const auto add_polygon = [&](const char* name, int on, const char* wkt) {
    OGRFeature feature(zones->GetLayerDefn());
    feature.SetField("zone", name);
    feature.SetField("active", on);
    OGRGeometry* geometry = nullptr;
    ASSERT_EQ(OGRGeometryFactory::createFromWkt(wkt, nullptr, &geometry), OGRERR_NONE);
    feature.SetGeometryDirectly(geometry);
    ASSERT_EQ(zones->CreateFeature(&feature), OGRERR_NONE);
  };
  add_polygon("A", 1, "POLYGON ((1010 2010, 1020 2010, 1020 2020, 1010 2020, 1010 2010))");
  add_polygon("B", 1, "POLYGON ((1030 2010, 1040 2010, 1040 2020, 1030 2020, 1030 2010))");
  add_polygon("A", 0, "POLYGON ((1050 2010, 1060 2010, 1060 2020, 1050 2020, 1050 2010))");
  OGRLayer* blocks = d->CreateLayer("blocks", &srs, wkbPoint, nullptr);
  OGRFeature point(blocks->GetLayerDefn());
  point.SetGeometryDirectly(new OGRPoint(1025, 2030));
  ASSERT_EQ(blocks->CreateFeature(&point), OGRERR_NONE);
}

// layer chooses one layer of a multi-layer file, where filters its features as OGR's
// SetAttributeFilter does; a multi-layer file without layer, an unknown layer and a bad where
// clause are errors naming the key.
TEST(ReadReleaseGeometries, LayerAndWhereChooseFeaturesOfAGeoPackage) {
  const auto dir = testing::FreshDir("layers");
  WriteTwoLayerGeoPackage(dir / "release.gpkg");
  // A DEM of 7 x 7 nodes of 10 m at x 1005 .. 1065, y 1985 .. 2045 in the same CRS.
  testing::WriteGdalRaster(dir / "dem.tif",
                           std::vector<std::vector<double>>(7, std::vector<double>(7, 500.0)),
                           {1000.0, 10.0, 0.0, 2050.0, 0.0, -10.0}, 31287, std::nullopt);
  const std::string scene =
      "[terrain]\ndem = \"dem.tif\"\n"
      "[rock]\nshape = { box = [1, 1, 1] }\n[release]\nfile = \"release.gpkg\"\nrocks = 2\n";
  const auto load = [&](const std::string& extra) {
    testing::WriteText(dir / "scene.toml", scene + extra);
    return LoadScene((dir / "scene.toml").string());
  };
  const auto error = [&](const std::string& extra) {
    try {
      load(extra);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  const std::string several = error("");
  EXPECT_NE(several.find("scene.toml:6: release.file: "), std::string::npos) << several;
  EXPECT_NE(several.find("has 2 layers ('zones', 'blocks'): choose one with layer"),
            std::string::npos)
      << several;

  const SceneFile zones = load("layer = \"zones\"\n");
  ASSERT_EQ(zones.release.releases.size(), 3u);
  EXPECT_EQ(zones.release.releases[0].kind, Kind::kPolygon);
  const SceneFile blocks = load("layer = \"blocks\"\n");
  ASSERT_EQ(blocks.release.releases.size(), 1u);
  EXPECT_EQ(blocks.release.releases[0].rings[0][0], Eigen::Vector2d(1025, 2030));

  const SceneFile a = load("layer = \"zones\"\nwhere = \"zone = 'A' AND active = 1\"\n");
  ASSERT_EQ(a.release.releases.size(), 1u);
  EXPECT_EQ(a.release.releases[0].rings[0][0], Eigen::Vector2d(1010, 2010));
  EXPECT_EQ(load("layer = \"zones\"\nwhere = \"zone = 'A'\"\n").release.releases.size(), 2u);

  const std::string unknown = error("layer = \"zone\"\n");
  EXPECT_NE(unknown.find("scene.toml:8: release.layer: "), std::string::npos) << unknown;
  EXPECT_NE(unknown.find("has no layer 'zone' (its layers: 'zones', 'blocks')"), std::string::npos)
      << unknown;
  const std::string bad = error("layer = \"zones\"\nwhere = \"zone = = 'A'\"\n");
  EXPECT_NE(bad.find("scene.toml:9: release.where: 'zone = = 'A'' is not a valid filter"),
            std::string::npos)
      << bad;
  const std::string nothing = error("layer = \"zones\"\nwhere = \"zone = 'C'\"\n");
  EXPECT_NE(nothing.find("has no point, line or polygon where zone = 'C'"), std::string::npos)
      << nothing;
  testing::WriteText(dir / "scene.toml",
                     "[terrain]\nplane = { slope_deg = 30, slope_length_m = 20, runout_m = 10, "
                     "width_m = 20 }\n[rock]\nshape = { box = [1, 1, 1] }\n[release]\n"
                     "points = [[5, 1]]\nwhere = \"zone = 'A'\"\n");
  try {
    LoadScene((dir / "scene.toml").string());
    ADD_FAILURE() << "where without file";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("release.where: chooses features of a vector file"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace talus::io
