#include "io/quicklook.hpp"

#include <gdal_priv.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "common/atomic_file.hpp"
#include "io/raster.hpp"

namespace talus::io {
namespace {

using Rgb = std::array<double, 3>;

// Yellow (low) through orange to dark red (high), t in [0, 1].
Rgb Ramp(double t) {
  t = std::clamp(t, 0.0, 1.0);
  const Rgb stops[] = {{255, 255, 150}, {253, 141, 60}, {189, 0, 38}, {90, 0, 20}};
  const double s = t * 3;
  const int k = std::min(2, static_cast<int>(s));
  const double f = s - k;
  return {stops[k][0] + f * (stops[k + 1][0] - stops[k][0]),
          stops[k][1] + f * (stops[k + 1][1] - stops[k][1]),
          stops[k][2] + f * (stops[k + 1][2] - stops[k][2])};
}

}  // namespace

const ensemble::RasterLayer* QuickLookLayer(const std::vector<ensemble::RasterLayer>& layers) {
  for (const char* name : {"reach_probability", "energy_max", "speed_max", "passages"})
    for (const ensemble::RasterLayer& l : layers)
      if (l.name == name) return &l;
  return nullptr;
}

void WriteQuickLookPng(const std::string& path, const Heightfield& dem,
                       const ensemble::RasterLayer* layer,
                       const std::vector<std::vector<Eigen::Vector2d>>& paths,
                       const std::vector<MapMarker>& markers) {
  const GridGeometry& g = dem.grid;
  const int scale = std::max(1, 900 / std::max(g.nx, g.ny));  // pixels per cell
  const int w = g.nx * scale, h = g.ny * scale;
  std::vector<Rgb> image(static_cast<std::size_t>(w) * h);
  auto z = [&](int i, int j) {
    i = std::clamp(i, 0, g.nx - 1);
    j = std::clamp(j, 0, g.ny - 1);
    return dem.z_m[static_cast<std::size_t>(j) * g.nx + i];
  };
  // Overlay scaling: [0, largest value] (energy on a log scale).
  double top = 0;
  const bool log_scale = layer && layer->name.rfind("energy", 0) == 0;
  if (layer) {
    for (float v : layer->values)
      if (v != ensemble::RasterLayer::kNoData) top = std::max(top, double(v));
  }
  // Hillshade: sun from the north-west, 45 degrees up.
  const double azimuth = 315 * std::numbers::pi / 180, altitude = 45 * std::numbers::pi / 180;
  const Eigen::Vector3d sun(std::sin(azimuth) * std::cos(altitude),
                            std::cos(azimuth) * std::cos(altitude), std::sin(altitude));
  for (int j = 0; j < g.ny; ++j)
    for (int i = 0; i < g.nx; ++i) {
      const double here = z(i, j);
      Rgb colour = {255, 255, 255};  // nodata: white
      if (!std::isnan(here)) {
        double dzdx = (z(i + 1, j) - z(i - 1, j)) / (2 * g.dx_m);
        double dzdy = (z(i, j + 1) - z(i, j - 1)) / (2 * g.dy_m);
        if (std::isnan(dzdx)) dzdx = 0;
        if (std::isnan(dzdy)) dzdy = 0;
        const double shade = std::max(0.0, Eigen::Vector3d(-dzdx, -dzdy, 1).normalized().dot(sun));
        const double grey = 60 + 180 * shade;
        colour = {grey, grey, grey};
        const std::size_t c = static_cast<std::size_t>(j) * g.nx + i;
        if (layer && layer->values[c] != ensemble::RasterLayer::kNoData && layer->values[c] > 0 &&
            top > 0) {
          const double v = layer->values[c];
          const double t = log_scale ? std::log1p(v) / std::log1p(top) : v / top;
          const Rgb ramp = Ramp(t);
          for (int k = 0; k < 3; ++k) colour[k] = 0.25 * colour[k] + 0.75 * ramp[k];
        }
      }
      for (int dy = 0; dy < scale; ++dy)
        for (int dx = 0; dx < scale; ++dx)
          image[static_cast<std::size_t>((g.ny - 1 - j) * scale + dy) * w + i * scale + dx] =
              colour;
    }
  // Paths: translucent blue lines (one dot per half pixel, blended once per dot).
  auto pixel = [&](const Eigen::Vector2d& p) {
    return Eigen::Vector2d((p.x() - g.x0_m + 0.5 * g.dx_m) / g.dx_m * scale,
                           (g.y_max_m() + 0.5 * g.dy_m - p.y()) / g.dy_m * scale);
  };
  for (const auto& line : paths)
    for (std::size_t k = 1; k < line.size(); ++k) {
      const Eigen::Vector2d a = pixel(line[k - 1]), b = pixel(line[k]);
      const int n = std::max(1, static_cast<int>(2 * (b - a).norm()));
      for (int s = 0; s <= n; ++s) {
        const Eigen::Vector2d p = a + (double(s) / n) * (b - a);
        const int x = static_cast<int>(p.x()), y = static_cast<int>(p.y());
        if (x < 0 || y < 0 || x >= w || y >= h) continue;
        Rgb& c = image[static_cast<std::size_t>(y) * w + x];
        c = {0.5 * c[0] + 0.5 * 20, 0.5 * c[1] + 0.5 * 60, 0.5 * c[2] + 0.5 * 200};
      }
    }

  for (const MapMarker& m : markers) {
    const Eigen::Vector2d centre = pixel(m.xy_m);
    for (int dy = -m.radius_px; dy <= m.radius_px; ++dy)
      for (int dx = -m.radius_px; dx <= m.radius_px; ++dx) {
        if (dx * dx + dy * dy > m.radius_px * m.radius_px) continue;
        const int x = static_cast<int>(centre.x()) + dx, y = static_cast<int>(centre.y()) + dy;
        if (x < 0 || y < 0 || x >= w || y >= h) continue;
        image[static_cast<std::size_t>(y) * w + x] = {double(m.rgb[0]), double(m.rgb[1]),
                                                      double(m.rgb[2])};
      }
  }

  RegisterGdal();
  GDALDriver* mem = GetGDALDriverManager()->GetDriverByName("MEM");
  GDALDriver* png = GetGDALDriverManager()->GetDriverByName("PNG");
  if (!mem || !png) throw std::runtime_error("GDAL lacks the MEM or PNG driver");
  GDALDataset* canvas = mem->Create("", w, h, 3, GDT_Byte, nullptr);
  std::vector<unsigned char> band(image.size());
  for (int k = 0; k < 3; ++k) {
    for (std::size_t p = 0; p < image.size(); ++p)
      band[p] = static_cast<unsigned char>(std::lround(std::clamp(image[p][k], 0.0, 255.0)));
    if (canvas->GetRasterBand(k + 1)->RasterIO(GF_Write, 0, 0, w, h, band.data(), w, h, GDT_Byte, 0,
                                               0) != CE_None) {
      GDALClose(canvas);
      throw std::runtime_error("cannot draw " + path);
    }
  }
  AtomicFile file(path);
  GDALDataset* written =
      png->CreateCopy(file.temp_path().c_str(), canvas, FALSE, nullptr, nullptr, nullptr);
  GDALClose(canvas);
  if (!written) throw std::runtime_error("cannot write " + path + ": " + CPLGetLastErrorMsg());
  GDALClose(written);
  file.Commit();
}

}  // namespace talus::io
