#pragma once
// Helpers for the I/O tests: a fresh temporary directory, text files, and small GeoTIFFs written
// with GDAL directly (north-up, rows from the north, as any GIS writes them).

#include <gdal_priv.h>
#include <gtest/gtest.h>
#include <ogr_spatialref.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "io/raster.hpp"
#include "tests/test_tmp.hpp"

namespace talus::io::testing {

inline std::filesystem::path FreshDir(const std::string& name) {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  std::filesystem::path dir =
      talus::testing::TestTmpRoot() / "talus_io_tests" /
      (std::string(info->test_suite_name()) + "." + info->name() + "." + name);
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

inline void WriteText(const std::filesystem::path& path, const std::string& text) {
  std::ofstream(path) << text;
}

inline std::string Wkt(int epsg) {
  OGRSpatialReference srs;
  srs.importFromEPSG(epsg);
  char* wkt = nullptr;
  srs.exportToWkt(&wkt);
  std::string out = wkt;
  CPLFree(wkt);
  return out;
}

// rows: GDAL order (row 0 is the northern edge). gt: GDAL geotransform. epsg 0: no CRS.
inline void WriteGdalRaster(const std::filesystem::path& path,
                            const std::vector<std::vector<double>>& rows,
                            const std::array<double, 6>& gt, int epsg, std::optional<double> nodata,
                            const char* driver_name = "GTiff") {
  RegisterGdal();
  const int ny = static_cast<int>(rows.size()), nx = static_cast<int>(rows[0].size());
  GDALDriver* mem = GetGDALDriverManager()->GetDriverByName("MEM");
  GDALDataset* d = mem->Create("", nx, ny, 1, GDT_Float64, nullptr);
  std::array<double, 6> g = gt;
  d->SetGeoTransform(g.data());
  if (epsg) {
    OGRSpatialReference srs;
    srs.importFromEPSG(epsg);
    d->SetSpatialRef(&srs);
  }
  if (nodata) d->GetRasterBand(1)->SetNoDataValue(*nodata);
  std::vector<double> flat;
  for (const auto& r : rows) flat.insert(flat.end(), r.begin(), r.end());
  EXPECT_EQ(
      d->GetRasterBand(1)->RasterIO(GF_Write, 0, 0, nx, ny, flat.data(), nx, ny, GDT_Float64, 0, 0),
      CE_None);
  GDALDriver* out = GetGDALDriverManager()->GetDriverByName(driver_name);
  GDALDataset* copy = out->CreateCopy(path.c_str(), d, FALSE, nullptr, nullptr, nullptr);
  ASSERT_NE(copy, nullptr);
  GDALClose(copy);
  GDALClose(d);
}

}  // namespace talus::io::testing
