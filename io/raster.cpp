#include "io/raster.hpp"

#include <cpl_string.h>
#include <gdal_alg.h>
#include <gdal_priv.h>
#include <gdal_utils.h>
#include <ogr_geometry.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <cmath>
#include <filesystem>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <type_traits>

#include "common/atomic_file.hpp"
#include "common/error.hpp"

namespace talus::io {
namespace {

struct DatasetCloser {
  void operator()(GDALDataset* d) const { GDALClose(d); }
};
using Dataset = std::unique_ptr<GDALDataset, DatasetCloser>;

constexpr std::array<const char*, 2> kRasterFormats = {"gtiff", "cog"};

}  // namespace

constinit const EnumNames kRasterFormatNames{"format", kRasterFormats};

const char* ToString(RasterFormat format) { return kRasterFormatNames.NameOf(format); }

void RegisterGdal() {
  static std::once_flag once;
  std::call_once(once, [] { GDALAllRegister(); });
}

namespace {

// The raster of an open dataset (see ReadRaster); `path` and `what` name it in errors.
Raster RasterOf(GDALDataset* dataset, const std::string& path, const std::string& what) {
  if (dataset->GetRasterCount() < 1) throw InputError(what + ": " + path + " has no raster band");
  double gt[6];
  if (dataset->GetGeoTransform(gt) != CE_None)
    throw InputError(what + ": " + path + " has no georeferencing (geotransform)");
  if (gt[2] != 0 || gt[4] != 0)
    throw InputError(what + ": " + path + " is rotated; only north-up rasters are supported");
  if (gt[1] <= 0 || gt[5] >= 0)
    throw InputError(what + ": " + path + " must be north-up with rows from north to south");

  Raster raster;
  const int nx = dataset->GetRasterXSize(), ny = dataset->GetRasterYSize();
  // The same bound as a plane's (solver/terrain.cpp): larger grids do not fit in memory.
  if (static_cast<double>(nx) * ny > kMaxRasterCells)
    throw InputError(what + ": " + path + " has " + std::to_string(nx) + " x " +
                     std::to_string(ny) + " cells, more than " +
                     std::to_string(static_cast<long>(kMaxRasterCells)) +
                     "; crop or resample it first (e.g. with gdalwarp)");
  raster.grid.nx = nx;
  raster.grid.ny = ny;
  raster.grid.dx_m = gt[1];
  raster.grid.dy_m = -gt[5];
  raster.grid.x0_m = gt[0] + 0.5 * gt[1];
  raster.grid.y0_m = gt[3] + (ny - 0.5) * gt[5];
  if (const OGRSpatialReference* srs = dataset->GetSpatialRef()) {
    char* wkt = nullptr;
    srs->exportToWkt(&wkt);
    raster.crs_wkt = wkt ? wkt : "";
    CPLFree(wkt);
  }
  GDALRasterBand* band = dataset->GetRasterBand(1);
  int has_nodata = 0;
  const double nodata = band->GetNoDataValue(&has_nodata);
  std::vector<double> rows(static_cast<std::size_t>(nx) * ny);
  if (band->RasterIO(GF_Read, 0, 0, nx, ny, rows.data(), nx, ny, GDT_Float64, 0, 0) != CE_None)
    throw InputError(what + ": GDAL cannot read the pixels of " + path + ": " +
                     CPLGetLastErrorMsg());
  raster.values.resize(rows.size());
  for (int r = 0; r < ny; ++r) {
    const int j = ny - 1 - r;  // GDAL row r (from the north) is grid row j (from the south)
    for (int i = 0; i < nx; ++i) {
      double v = rows[static_cast<std::size_t>(r) * nx + i];
      // Infinite values stay: callers reject them (an undeclared nodata, or a broken file).
      if ((has_nodata && (v == nodata || (std::isnan(nodata) && std::isnan(v)))) || std::isnan(v))
        v = std::nan("");
      raster.values[static_cast<std::size_t>(j) * nx + i] = v;
    }
  }
  return raster;
}

// Throws InputError when the raster reprojected to `target_crs_wkt` would have more than
// kMaxRasterCells cells: the size gdalwarp chooses (GDALSuggestedWarpOutput), computed from the
// source's outline without reading a pixel, before the warp builds it in memory.
void CheckWarpedSize(GDALDataset* dataset, const std::string& path, const std::string& source_wkt,
                     const std::string& target_crs_wkt, const std::string& what) {
  CPLStringList options;
  options.SetNameValue("DST_SRS", target_crs_wkt.c_str());
  CPLErrorReset();
  void* transformer =
      GDALCreateGenImgProjTransformer2(GDALDataset::ToHandle(dataset), nullptr, options.List());
  if (!transformer)
    throw InputError(what + ": cannot reproject " + path + " from " + DescribeCrs(source_wkt) +
                     " to " + DescribeCrs(target_crs_wkt) + ": " + CPLGetLastErrorMsg());
  double gt[6];
  int nx = 0, ny = 0;
  const CPLErr suggested = GDALSuggestedWarpOutput(
      GDALDataset::ToHandle(dataset), GDALGenImgProjTransform, transformer, gt, &nx, &ny);
  GDALDestroyGenImgProjTransformer(transformer);
  if (suggested != CE_None)
    throw InputError(what + ": cannot reproject " + path + " from " + DescribeCrs(source_wkt) +
                     " to " + DescribeCrs(target_crs_wkt) + ": " + CPLGetLastErrorMsg());
  if (static_cast<double>(nx) * ny > kMaxRasterCells)
    throw InputError(what + ": " + path + " would have " + std::to_string(nx) + " x " +
                     std::to_string(ny) + " cells once reprojected from " +
                     DescribeCrs(source_wkt) + " to " + DescribeCrs(target_crs_wkt) +
                     ", more than " + std::to_string(static_cast<long>(kMaxRasterCells)) +
                     "; crop or resample it first (e.g. with gdalwarp -t_srs and -tr)");
}

}  // namespace

Raster ReadRaster(const std::string& path, const std::string& what) {
  return ReadRasterIn(path, "", what, nullptr);
}

Raster ReadRasterIn(const std::string& path, const std::string& target_crs_wkt,
                    const std::string& what, std::string* reprojected_from) {
  RegisterGdal();
  if (!std::filesystem::exists(path)) throw InputError(what + ": file not found: " + path);
  CPLErrorReset();
  Dataset dataset(static_cast<GDALDataset*>(GDALOpen(path.c_str(), GA_ReadOnly)));
  if (!dataset) throw InputError(what + ": GDAL cannot read " + path + ": " + CPLGetLastErrorMsg());
  if (dataset->GetRasterCount() < 1) throw InputError(what + ": " + path + " has no raster band");
  const OGRSpatialReference* srs = dataset->GetSpatialRef();
  std::string source_wkt;
  if (srs) {
    char* wkt = nullptr;
    srs->exportToWkt(&wkt);
    source_wkt = wkt ? wkt : "";
    CPLFree(wkt);
  }
  if (target_crs_wkt.empty() || source_wkt.empty() || SameCrs(source_wkt, target_crs_wkt))
    return RasterOf(dataset.get(), path, what);
  CheckWarpedSize(dataset.get(), path, source_wkt, target_crs_wkt, what);
  // gdalwarp -t_srs <target> -r near -ot Float64 -dstnodata nan -of MEM: every value stays a
  // value of the file (nearest neighbour), cells off the file are nodata.
  const std::vector<std::string> args = {"-t_srs",  target_crs_wkt, "-r",  "near", "-ot",
                                         "Float64", "-dstnodata",   "nan", "-of",  "MEM"};
  std::vector<char*> argv;
  for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  std::unique_ptr<GDALWarpAppOptions, decltype(&GDALWarpAppOptionsFree)> options(
      GDALWarpAppOptionsNew(argv.data(), nullptr), &GDALWarpAppOptionsFree);
  GDALDatasetH source = dataset.get();
  int usage_error = 0;
  CPLErrorReset();
  Dataset warped(
      GDALDataset::FromHandle(GDALWarp("", nullptr, 1, &source, options.get(), &usage_error)));
  if (!warped)
    throw InputError(what + ": cannot reproject " + path + " from " + DescribeCrs(source_wkt) +
                     " to " + DescribeCrs(target_crs_wkt) + ": " + CPLGetLastErrorMsg());
  if (reprojected_from) *reprojected_from = source_wkt;
  Raster raster = RasterOf(warped.get(), path + " (reprojected)", what);
  raster.crs_wkt = target_crs_wkt;
  return raster;
}

bool SameCrs(const std::string& a_wkt, const std::string& b_wkt) {
  if (a_wkt == b_wkt) return true;
  OGRSpatialReference a, b;
  if (a.importFromWkt(a_wkt.c_str()) != OGRERR_NONE ||
      b.importFromWkt(b_wkt.c_str()) != OGRERR_NONE)
    return false;
  return a.IsSame(&b);
}

bool IsGeographicCrs(const std::string& crs_wkt) {
  if (crs_wkt.empty()) return false;
  OGRSpatialReference srs;
  if (srs.importFromWkt(crs_wkt.c_str()) != OGRERR_NONE) return false;
  return srs.IsGeographic();
}

std::string DescribeCrs(const std::string& crs_wkt) {
  if (crs_wkt.empty()) return "no CRS";
  OGRSpatialReference srs;
  if (srs.importFromWkt(crs_wkt.c_str()) != OGRERR_NONE) return "an unreadable CRS";
  const char* name = srs.GetName();
  std::string named = name ? name : "an unnamed CRS";
  const char* authority = srs.GetAuthorityName(nullptr);
  const char* code = srs.GetAuthorityCode(nullptr);
  if (!authority || !code) return named;
  return std::string(authority) + ":" + code + " (" + named + ")";
}

std::string UtmEpsgFor(double lon_deg, double lat_deg) {
  if (!(std::abs(lon_deg) <= 180 && std::abs(lat_deg) <= 84)) return "";
  const int zone = std::clamp(static_cast<int>(std::floor((lon_deg + 180) / 6)) + 1, 1, 60);
  return "EPSG:" + std::to_string((lat_deg >= 0 ? 32600 : 32700) + zone);
}

std::array<double, 6> GeoTransformOf(const GridGeometry& grid) {
  return {grid.x0_m - 0.5 * grid.dx_m,      grid.dx_m, 0.0,
          grid.y_max_m() + 0.5 * grid.dy_m, 0.0,       -grid.dy_m};
}

std::vector<int> RasterisePolygons(
    const GridGeometry& grid,
    const std::vector<std::vector<std::vector<Eigen::Vector2d>>>& polygons,
    const std::vector<int>& burn) {
  RegisterGdal();
  GDALDriver* mem = GetGDALDriverManager()->GetDriverByName("MEM");
  if (!mem) throw std::runtime_error("GDAL has no MEM driver");
  Dataset dataset(mem->Create("", grid.nx, grid.ny, 1, GDT_Int32, nullptr));
  if (!dataset)
    throw std::runtime_error("cannot rasterise polygons: " + std::string(CPLGetLastErrorMsg()));
  std::array<double, 6> gt = GeoTransformOf(grid);
  dataset->SetGeoTransform(gt.data());
  GDALRasterBand* band = dataset->GetRasterBand(1);
  band->Fill(-1);
  std::vector<std::unique_ptr<OGRPolygon>> geometries;
  std::vector<OGRGeometryH> handles;
  std::vector<double> values;
  for (std::size_t k = 0; k < polygons.size(); ++k) {
    auto polygon = std::make_unique<OGRPolygon>();
    for (const auto& ring : polygons[k]) {
      auto r = std::make_unique<OGRLinearRing>();
      for (const Eigen::Vector2d& p : ring) r->addPoint(p.x(), p.y());
      r->closeRings();
      polygon->addRingDirectly(r.release());
    }
    handles.push_back(OGRGeometry::ToHandle(polygon.get()));
    geometries.push_back(std::move(polygon));
    values.push_back(burn[k]);
  }
  int band_list[] = {1};
  // No ALL_TOUCHED: a node is burnt when the cell centre is inside; polygons are burnt in order.
  if (GDALRasterizeGeometries(GDALDataset::ToHandle(dataset.get()), 1, band_list,
                              static_cast<int>(handles.size()), handles.data(), nullptr, nullptr,
                              values.data(), nullptr, nullptr, nullptr) != CE_None)
    throw std::runtime_error("cannot rasterise polygons: " + std::string(CPLGetLastErrorMsg()));
  std::vector<int> rows(static_cast<std::size_t>(grid.nx) * grid.ny);
  if (band->RasterIO(GF_Read, 0, 0, grid.nx, grid.ny, rows.data(), grid.nx, grid.ny, GDT_Int32, 0,
                     0) != CE_None)
    throw std::runtime_error("cannot rasterise polygons: " + std::string(CPLGetLastErrorMsg()));
  std::vector<int> out(rows.size());
  for (int r = 0; r < grid.ny; ++r) {
    const int j = grid.ny - 1 - r;  // GDAL row r (from the north) is grid row j (from the south)
    std::copy_n(rows.begin() + static_cast<long>(r) * grid.nx, grid.nx,
                out.begin() + static_cast<long>(j) * grid.nx);
  }
  return out;
}

namespace {

// WriteGeoTiff for cells of type T (float: Float32, std::int32_t: Int32), row j from the south.
template <class T>
void WriteGeoTiffOf(const std::string& path, const GridGeometry& grid, const std::string& crs_wkt,
                    const std::vector<T>& values, bool has_nodata, double nodata,
                    const RasterMetadata& metadata, RasterFormat format) {
  constexpr GDALDataType kType = std::is_same_v<T, float> ? GDT_Float32 : GDT_Int32;
  RegisterGdal();
  const bool cog = format == RasterFormat::kCog;
  GDALDriver* driver = GetGDALDriverManager()->GetDriverByName(cog ? "COG" : "GTiff");
  GDALDriver* memory = GetGDALDriverManager()->GetDriverByName("MEM");
  if (!driver || !memory)
    throw std::runtime_error(std::string("GDAL has no ") + (cog ? "COG" : "GTiff") + " driver");
  AtomicFile file(path);
  {
    // The COG driver only copies a finished dataset: it is built in memory first. Deflate at
    // level 1: half the instructions of the default level 6 for 5 % more bytes (bench/README.md,
    // "What a run pays besides its rocks").
    const char* gtiff_options[] = {"COMPRESS=DEFLATE", "ZLEVEL=1", "TILED=YES", nullptr};
    Dataset dataset(cog ? memory->Create("", grid.nx, grid.ny, 1, kType, nullptr)
                        : driver->Create(file.temp_path().c_str(), grid.nx, grid.ny, 1, kType,
                                         const_cast<char**>(gtiff_options)));
    if (!dataset) throw std::runtime_error("cannot create " + path + ": " + CPLGetLastErrorMsg());
    std::array<double, 6> gt = GeoTransformOf(grid);
    dataset->SetGeoTransform(gt.data());
    if (!crs_wkt.empty()) {
      OGRSpatialReference srs;
      srs.importFromWkt(crs_wkt.c_str());
      dataset->SetSpatialRef(&srs);
    }
    for (const auto& [name, value] : metadata.items)
      dataset->SetMetadataItem(name.c_str(), value.c_str());
    GDALRasterBand* band = dataset->GetRasterBand(1);
    if (has_nodata) band->SetNoDataValue(nodata);
    band->SetDescription(metadata.description.c_str());
    if (!metadata.unit.empty()) band->SetUnitType(metadata.unit.c_str());
    std::vector<T> rows(values.size());
    for (int j = 0; j < grid.ny; ++j) {
      const int r = grid.ny - 1 - j;
      std::copy_n(values.begin() + static_cast<long>(j) * grid.nx, grid.nx,
                  rows.begin() + static_cast<long>(r) * grid.nx);
    }
    if (band->RasterIO(GF_Write, 0, 0, grid.nx, grid.ny, rows.data(), grid.nx, grid.ny, kType, 0,
                       0) != CE_None)
      throw std::runtime_error("cannot write " + path + ": " + CPLGetLastErrorMsg());
    if (cog) {
      // Nearest-neighbour overviews show cell values that exist; one thread keeps the bytes fixed.
      const char* cog_options[] = {
          "COMPRESS=DEFLATE", "LEVEL=1",       "OVERVIEWS=AUTO", "RESAMPLING=NEAREST",
          "NUM_THREADS=1",    "BLOCKSIZE=512", nullptr};
      CPLErrorReset();
      Dataset copy(driver->CreateCopy(file.temp_path().c_str(), dataset.get(), FALSE,
                                      const_cast<char**>(cog_options), nullptr, nullptr));
      if (!copy) throw std::runtime_error("cannot write " + path + ": " + CPLGetLastErrorMsg());
      copy.reset();  // flushes it
      if (CPLGetLastErrorType() >= CE_Failure)
        throw std::runtime_error("cannot write " + path + ": " + CPLGetLastErrorMsg());
    }
    CPLErrorReset();
  }  // closing the dataset flushes it; a failure there is reported through CPLGetLastErrorType
  if (CPLGetLastErrorType() >= CE_Failure)
    throw std::runtime_error("cannot write " + path + ": " + CPLGetLastErrorMsg());
  file.Commit();
}

}  // namespace

void WriteGeoTiff(const std::string& path, const GridGeometry& grid, const std::string& crs_wkt,
                  const std::vector<float>& values, bool has_nodata, double nodata,
                  const RasterMetadata& metadata, RasterFormat format) {
  WriteGeoTiffOf(path, grid, crs_wkt, values, has_nodata, nodata, metadata, format);
}

void WriteGeoTiff(const std::string& path, const GridGeometry& grid, const std::string& crs_wkt,
                  const std::vector<std::int32_t>& values, bool has_nodata, double nodata,
                  const RasterMetadata& metadata, RasterFormat format) {
  WriteGeoTiffOf(path, grid, crs_wkt, values, has_nodata, nodata, metadata, format);
}

}  // namespace talus::io
