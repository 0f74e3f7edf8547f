// Derives cases/tirol/ground.tif from the DEM's slope: a documented first guess of the ground
// categories (README.md). Build and run from cases/tirol:
//   g++ -std=c++20 -O2 -I/usr/include/gdal make_ground.cpp -lgdal -o /tmp/make_ground
//   /tmp/make_ground dem.tif ground.tif
// Slope from central differences (Horn's 3x3 kernel); codes as in docs/model.md:
//   slope >= 45 deg: 7 extra_hard (rock face, bedrock)
//   35 .. 45 deg:    6 hard (rock scree, talus)
//   25 .. 35 deg:    5 medium_hard (shallow soil on steep slopes)
//   < 25 deg:        4 medium (meadow, valley floor)
//   nodata (also cells next to nodata): 255, the scene's default.

#include <gdal_priv.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <vector>

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: make_ground DEM OUT\n");
    return 2;
  }
  GDALAllRegister();
  GDALDataset* dem = static_cast<GDALDataset*>(GDALOpen(argv[1], GA_ReadOnly));
  if (!dem) return 1;
  const int nx = dem->GetRasterXSize(), ny = dem->GetRasterYSize();
  double gt[6];
  dem->GetGeoTransform(gt);
  GDALRasterBand* band = dem->GetRasterBand(1);
  int has_nodata = 0;
  const double nodata = band->GetNoDataValue(&has_nodata);
  std::vector<double> z(static_cast<std::size_t>(nx) * ny);
  if (band->RasterIO(GF_Read, 0, 0, nx, ny, z.data(), nx, ny, GDT_Float64, 0, 0) != CE_None) return 1;
  auto at = [&](int c, int r) { return z[static_cast<std::size_t>(r) * nx + c]; };
  auto valid = [&](int c, int r) {
    return c >= 0 && r >= 0 && c < nx && r < ny && !(has_nodata && at(c, r) == nodata);
  };
  std::vector<unsigned char> code(z.size(), 255);
  int counts[256] = {};
  for (int r = 0; r < ny; ++r)
    for (int c = 0; c < nx; ++c) {
      bool ok = true;
      for (int dr = -1; dr <= 1; ++dr)
        for (int dc = -1; dc <= 1; ++dc) ok = ok && valid(c + dc, r + dr);
      if (!ok) continue;
      const double dzdx = ((at(c + 1, r - 1) + 2 * at(c + 1, r) + at(c + 1, r + 1)) -
                           (at(c - 1, r - 1) + 2 * at(c - 1, r) + at(c - 1, r + 1))) / (8 * gt[1]);
      const double dzdy = ((at(c - 1, r + 1) + 2 * at(c, r + 1) + at(c + 1, r + 1)) -
                           (at(c - 1, r - 1) + 2 * at(c, r - 1) + at(c + 1, r - 1))) / (8 * -gt[5]);
      const double slope_deg = std::atan(std::hypot(dzdx, dzdy)) * 180 / std::numbers::pi;
      const unsigned char k = slope_deg >= 45 ? 7 : slope_deg >= 35 ? 6 : slope_deg >= 25 ? 5 : 4;
      code[static_cast<std::size_t>(r) * nx + c] = k;
      ++counts[k];
    }
  GDALDriver* gtiff = GetGDALDriverManager()->GetDriverByName("GTiff");
  const char* options[] = {"COMPRESS=DEFLATE", nullptr};
  GDALDataset* out = gtiff->Create(argv[2], nx, ny, 1, GDT_Byte, const_cast<char**>(options));
  out->SetGeoTransform(gt);
  out->SetSpatialRef(dem->GetSpatialRef());
  out->GetRasterBand(1)->SetNoDataValue(255);
  if (out->GetRasterBand(1)->RasterIO(GF_Write, 0, 0, nx, ny, code.data(), nx, ny, GDT_Byte, 0, 0) != CE_None)
    return 1;
  GDALClose(out);
  GDALClose(dem);
  std::printf("cells: medium %d, medium_hard %d, hard %d, extra_hard %d\n", counts[4], counts[5], counts[6],
              counts[7]);
  return 0;
}
