#include "io/quicklook.hpp"

#include <cairo.h>
#include <png.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <csetjmp>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <memory>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/atomic_file.hpp"
#include "common/format.hpp"
#include "common/rounding.hpp"

namespace talus::io {
namespace {

using Rgb = std::array<double, 3>;

constexpr int kPanelWidth = 250;  // legend panel, pixels
constexpr int kMinHeight = 380;   // the legend needs this much height
constexpr int kMapPixels = 900;   // the map's longer side, at most

std::string Number(double value) { return FormatDouble(value, "%.3g"); }

void SetColour(cairo_t* cr, const std::array<unsigned char, 3>& rgb, double alpha = 1) {
  cairo_set_source_rgba(cr, rgb[0] / 255.0, rgb[1] / 255.0, rgb[2] / 255.0, alpha);
}

void Text(cairo_t* cr, double x, double y, double size, const std::string& text,
          bool bold = false) {
  cairo_select_font_face(cr, "DejaVu Sans", CAIRO_FONT_SLANT_NORMAL,
                         bold ? CAIRO_FONT_WEIGHT_BOLD : CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(cr, size);
  cairo_move_to(cr, x, y);
  cairo_show_text(cr, text.c_str());
}

double TextWidth(cairo_t* cr, double size, const std::string& text) {
  cairo_select_font_face(cr, "DejaVu Sans", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(cr, size);
  cairo_text_extents_t extents;
  cairo_text_extents(cr, text.c_str(), &extents);
  return extents.x_advance;
}

// The hillshade of the DEM (sun from the north-west, 45° up) with the layer's classes on top,
// one colour per cell, into the image surface's pixels.
void PaintMap(cairo_surface_t* surface, const Heightfield& dem, const ensemble::RasterLayer* layer,
              const QuickLookLegend& legend, int scale) {
  const GridGeometry& g = dem.grid;
  auto z = [&](int i, int j) {
    i = std::clamp(i, 0, g.nx - 1);
    j = std::clamp(j, 0, g.ny - 1);
    return dem.z_m[static_cast<std::size_t>(j) * g.nx + i];
  };
  const double azimuth = 315 * std::numbers::pi / 180, altitude = 45 * std::numbers::pi / 180;
  const Eigen::Vector3d sun(std::sin(azimuth) * std::cos(altitude),
                            std::cos(azimuth) * std::cos(altitude), std::sin(altitude));
  cairo_surface_flush(surface);
  unsigned char* data = cairo_image_surface_get_data(surface);
  const int stride = cairo_image_surface_get_stride(surface);
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
        const int k = layer && layer->values[c] != ensemble::RasterLayer::kNoData
                          ? legend.ClassOf(layer->values[c])
                          : -1;
        if (k >= 0)
          for (int b = 0; b < 3; ++b)
            colour[b] = 0.25 * colour[b] + 0.75 * legend.classes[k].rgb[b];
      }
      // CAIRO_FORMAT_RGB24: one 32-bit word per pixel, 0x00RRGGBB in native byte order.
      const std::uint32_t word = (static_cast<std::uint32_t>(RoundHalfAway(colour[0])) << 16) |
                                 (static_cast<std::uint32_t>(RoundHalfAway(colour[1])) << 8) |
                                 static_cast<std::uint32_t>(RoundHalfAway(colour[2]));
      for (int dy = 0; dy < scale; ++dy) {
        auto* row = reinterpret_cast<std::uint32_t*>(
            data + static_cast<std::size_t>((g.ny - 1 - j) * scale + dy) * stride);
        for (int dx = 0; dx < scale; ++dx) row[i * scale + dx] = word;
      }
    }
  cairo_surface_mark_dirty(surface);
}

// Scale bar at the map's bottom left: four black and white quarters and the length.
void DrawScaleBar(cairo_t* cr, const GridGeometry& g, const QuickLookLayout& layout) {
  const double metres_per_pixel = g.dx_m / layout.scale;
  const double length_m = ScaleBarLength(0.25 * layout.map_width * metres_per_pixel);
  const double length_px = length_m / metres_per_pixel;
  const std::string label =
      length_m >= 1000 ? Number(length_m / 1000) + " km" : Number(length_m) + " m";
  const double x = 10, y = layout.map_height - 14;
  cairo_set_source_rgba(cr, 1, 1, 1, 0.8);
  cairo_rectangle(cr, x - 6, y - 22, length_px + 12 + TextWidth(cr, 12, label) + 8, 32);
  cairo_fill(cr);
  for (int q = 0; q < 4; ++q) {
    cairo_rectangle(cr, x + q * length_px / 4, y - 4, length_px / 4, 6);
    if (q % 2 == 0)
      cairo_set_source_rgb(cr, 0, 0, 0);
    else
      cairo_set_source_rgb(cr, 1, 1, 1);
    cairo_fill_preserve(cr);
    cairo_set_source_rgb(cr, 0, 0, 0);
    cairo_set_line_width(cr, 1);
    cairo_stroke(cr);
  }
  cairo_set_source_rgb(cr, 0, 0, 0);
  Text(cr, x, y - 9, 12, "0");
  Text(cr, x + length_px + 6, y + 2, 12, label);
}

// North arrow at the map's top right (the DEM is north up).
void DrawNorthArrow(cairo_t* cr, const QuickLookLayout& layout) {
  const double cx = layout.map_width - 24, top = 10;
  cairo_set_source_rgba(cr, 1, 1, 1, 0.8);
  cairo_rectangle(cr, cx - 14, top - 2, 28, 50);
  cairo_fill(cr);
  cairo_set_source_rgb(cr, 0, 0, 0);
  cairo_move_to(cr, cx, top + 2);
  cairo_line_to(cr, cx + 8, top + 26);
  cairo_line_to(cr, cx, top + 20);
  cairo_line_to(cr, cx - 8, top + 26);
  cairo_close_path(cr);
  cairo_fill(cr);
  Text(cr, cx - 5, top + 44, 14, "N", true);
}

void DrawLegend(cairo_t* cr, const ensemble::RasterLayer* layer, const QuickLookLegend& legend,
                std::size_t paths, const std::vector<MapMarker>& markers, std::size_t lines,
                const QuickLookLayout& layout) {
  const double x = layout.map_width + 16;
  double y = 28;
  cairo_set_source_rgb(cr, 0.97, 0.97, 0.97);
  cairo_rectangle(cr, layout.map_width, 0, layout.width - layout.map_width, layout.height);
  cairo_fill(cr);
  cairo_set_source_rgb(cr, 0, 0, 0);
  if (layer) {
    Text(cr, x, y, 14, legend.title, true);
    y += 12;
    for (std::size_t k = legend.classes.size(); k-- > 0;) {  // highest class on top
      const ColourClass& colour = legend.classes[k];
      SetColour(cr, colour.rgb);
      cairo_rectangle(cr, x, y + 4, 24, 16);
      cairo_fill_preserve(cr);
      cairo_set_source_rgb(cr, 0.3, 0.3, 0.3);
      cairo_set_line_width(cr, 1);
      cairo_stroke(cr);
      cairo_set_source_rgb(cr, 0, 0, 0);
      Text(cr, x + 32, y + 17, 12, colour.label);
      y += 22;
    }
    Text(cr, x, y + 16, 11, "no colour: no rock passed");
    y += 34;
  }
  if (paths > 0) {
    SetColour(cr, kPathRgb, 0.8);
    cairo_set_line_width(cr, 2);
    cairo_move_to(cr, x, y + 8);
    cairo_line_to(cr, x + 24, y + 8);
    cairo_stroke(cr);
    cairo_set_source_rgb(cr, 0, 0, 0);
    Text(cr, x + 32, y + 12, 12,
         "paths of " + std::to_string(paths) + (paths == 1 ? " rock" : " rocks"));
    y += 22;
  }
  if (lines > 0) {
    cairo_set_source_rgb(cr, 0, 0, 0);
    cairo_set_line_width(cr, 2.5);
    cairo_move_to(cr, x, y + 8);
    cairo_line_to(cr, x + 24, y + 8);
    cairo_stroke(cr);
    Text(cr, x + 32, y + 12, 12, lines == 1 ? "evaluation line" : "evaluation lines");
    y += 22;
  }
  std::vector<std::string> listed;
  for (const MapMarker& m : markers) {
    if (m.label.empty() || std::find(listed.begin(), listed.end(), m.label) != listed.end())
      continue;
    listed.push_back(m.label);
    SetColour(cr, m.rgb);
    cairo_arc(cr, x + 12, y + 8, std::max(3, m.radius_px), 0, 2 * std::numbers::pi);
    cairo_fill(cr);
    cairo_set_source_rgb(cr, 0, 0, 0);
    Text(cr, x + 32, y + 12, 12, m.label);
    y += 22;
  }
  cairo_set_source_rgb(cr, 0.35, 0.35, 0.35);
  Text(cr, x, layout.height - 12, 11, "hillshade: sun from the north-west");
}

// The quick-look's PNG encoding: zlib level 1 and each row as its difference from the row above
// ("up"). Against libpng's defaults (level 6, the best of five filters per row, which cairo's own
// writer takes) it encodes a 790 x 740 map 4.2 times as fast for 8 % more bytes (bench/README.md,
// "The quick-look's PNG").
constexpr int kPngLevel = 1;
constexpr int kPngFilter = PNG_FILTER_UP;

struct PngSink {
  std::string* out;
  char message[200];
};

// Writes `rows` (height rows of width RGB pixels, 8 bits each) to sink->out as a PNG. False with
// sink->message set when libpng fails. Only trivially destructible objects live in this frame,
// which libpng's errors leave by longjmp.
bool EncodeRgbPng(const unsigned char* rows, int width, int height, PngSink* sink) {
  png_structp png = png_create_write_struct(
      PNG_LIBPNG_VER_STRING, sink,
      [](png_structp p, png_const_charp message) {
        auto* s = static_cast<PngSink*>(png_get_error_ptr(p));
        std::snprintf(s->message, sizeof s->message, "%s", message);
        png_longjmp(p, 1);
      },
      [](png_structp, png_const_charp) {});
  if (png == nullptr) {
    std::snprintf(sink->message, sizeof sink->message, "libpng could not start");
    return false;
  }
  png_infop info = png_create_info_struct(png);
  if (info == nullptr || setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    return false;
  }
  png_set_write_fn(
      png, sink,
      [](png_structp p, png_bytep data, png_size_t length) {
        static_cast<PngSink*>(png_get_io_ptr(p))
            ->out->append(reinterpret_cast<char*>(data), length);
      },
      nullptr);
  png_set_IHDR(png, info, static_cast<png_uint_32>(width), static_cast<png_uint_32>(height), 8,
               PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
               PNG_FILTER_TYPE_DEFAULT);
  png_set_compression_level(png, kPngLevel);
  png_set_filter(png, PNG_FILTER_TYPE_BASE, kPngFilter);
  png_write_info(png, info);
  const std::size_t stride = 3 * static_cast<std::size_t>(width);
  for (int y = 0; y < height; ++y) png_write_row(png, rows + y * stride);
  png_write_end(png, info);
  png_destroy_write_struct(&png, &info);
  return true;
}

// The surface (CAIRO_FORMAT_RGB24: a 32-bit 0xXXRRGGBB per pixel) as a PNG.
std::string SurfacePng(cairo_surface_t* surface) {
  cairo_surface_flush(surface);
  const int width = cairo_image_surface_get_width(surface);
  const int height = cairo_image_surface_get_height(surface);
  const int stride = cairo_image_surface_get_stride(surface);
  const unsigned char* data = cairo_image_surface_get_data(surface);
  std::vector<unsigned char> rows(3 * static_cast<std::size_t>(width) * height);
  unsigned char* to = rows.data();
  for (int y = 0; y < height; ++y) {
    const unsigned char* from = data + static_cast<std::size_t>(y) * stride;
    for (int x = 0; x < width; ++x, to += 3) {
      std::uint32_t pixel;
      std::memcpy(&pixel, from + 4 * x, sizeof pixel);
      to[0] = static_cast<unsigned char>(pixel >> 16);
      to[1] = static_cast<unsigned char>(pixel >> 8);
      to[2] = static_cast<unsigned char>(pixel);
    }
  }
  std::string png;
  PngSink sink{&png, ""};
  if (!EncodeRgbPng(rows.data(), width, height, &sink))
    throw std::runtime_error(std::string("cannot encode the quick-look: ") + sink.message);
  return png;
}

}  // namespace

const ensemble::RasterLayer* QuickLookLayer(const std::vector<ensemble::RasterLayer>& layers) {
  for (const char* name : {"reach_probability", "energy_max", "speed_max", "passages"})
    for (const ensemble::RasterLayer& l : layers)
      if (l.name == name) return &l;
  return nullptr;
}

QuickLookLayout QuickLookLayoutOf(const GridGeometry& grid) {
  QuickLookLayout layout;
  layout.scale = std::max(1, kMapPixels / std::max(grid.nx, grid.ny));
  layout.map_width = grid.nx * layout.scale;
  layout.map_height = grid.ny * layout.scale;
  layout.width = layout.map_width + kPanelWidth;
  layout.height = std::max(layout.map_height, kMinHeight);
  return layout;
}

double ScaleBarLength(double at_most_m) {
  if (!(at_most_m > 0)) return 0;
  double decade = std::pow(10.0, std::floor(std::log10(at_most_m)));
  if (decade > at_most_m) decade /= 10;  // guards log10 rounding at exact powers of ten
  for (double step : {5.0, 2.0, 1.0})
    if (step * decade <= at_most_m) return step * decade;
  return decade;
}

namespace {
// A new image surface of the picture's size; throws when cairo cannot make one (out of memory).
cairo_surface_t* NewSurface(cairo_format_t format, int width, int height) {
  cairo_surface_t* surface = cairo_image_surface_create(format, width, height);
  if (cairo_surface_status(surface) != CAIRO_STATUS_SUCCESS) {
    const std::string why = cairo_status_to_string(cairo_surface_status(surface));
    cairo_surface_destroy(surface);
    throw std::runtime_error("cannot draw the quick-look: " + why);
  }
  return surface;
}
using Context = std::unique_ptr<cairo_t, decltype(&cairo_destroy)>;

// Map coordinates to the map's pixels: cell centres at pixel centres, north up.
Eigen::Vector2d PixelOf(const GridGeometry& g, const QuickLookLayout& layout,
                        const Eigen::Vector2d& p) {
  return Eigen::Vector2d((p.x() - g.x0_m + 0.5 * g.dx_m) / g.dx_m * layout.scale,
                         (g.y_max_m() + 0.5 * g.dy_m - p.y()) / g.dy_m * layout.scale);
}
}  // namespace

struct MapPathsLayer {
  std::unique_ptr<cairo_surface_t, decltype(&cairo_surface_destroy)> surface{nullptr,
                                                                             cairo_surface_destroy};
};

MapPaths::MapPaths(const GridGeometry& grid, const std::vector<std::vector<Eigen::Vector2d>>& paths)
    : count_(paths.size()) {
  if (std::none_of(paths.begin(), paths.end(), [](const auto& p) { return p.size() >= 2; })) return;
  const QuickLookLayout layout = QuickLookLayoutOf(grid);
  auto layer = std::make_shared<MapPathsLayer>();
  layer->surface.reset(NewSurface(CAIRO_FORMAT_ARGB32, layout.map_width, layout.map_height));
  const Context context(cairo_create(layer->surface.get()), cairo_destroy);
  cairo_t* cr = context.get();
  SetColour(cr, kPathRgb, kPathOpacity);
  cairo_set_line_width(cr, 1.5);
  cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
  for (const auto& line : paths) {
    if (line.size() < 2) continue;
    Eigen::Vector2d last = PixelOf(grid, layout, line.front());
    cairo_move_to(cr, last.x(), last.y());
    for (std::size_t k = 1; k < line.size(); ++k) {
      const Eigen::Vector2d p = PixelOf(grid, layout, line[k]);
      if (k + 1 < line.size() && (p - last).squaredNorm() < 1) continue;
      cairo_line_to(cr, p.x(), p.y());
      last = p;
    }
    cairo_stroke(cr);
  }
  cairo_surface_flush(layer->surface.get());
  layer_ = std::move(layer);
}

std::string QuickLookPng(const Heightfield& dem, const ensemble::RasterLayer* layer,
                         const std::vector<std::vector<Eigen::Vector2d>>& paths,
                         const std::vector<MapMarker>& markers, const std::vector<MapLine>& lines) {
  return QuickLookPngOf(dem, layer, MapPaths(dem.grid, paths), markers, lines);
}

std::string QuickLookPngOf(const Heightfield& dem, const ensemble::RasterLayer* layer,
                           const MapPaths& paths, const std::vector<MapMarker>& markers,
                           const std::vector<MapLine>& lines) {
  const GridGeometry& g = dem.grid;
  const QuickLookLayout layout = QuickLookLayoutOf(g);
  const QuickLookLegend legend = layer ? LegendOf(*layer) : QuickLookLegend{};
  const std::unique_ptr<cairo_surface_t, decltype(&cairo_surface_destroy)> surface(
      NewSurface(CAIRO_FORMAT_RGB24, layout.width, layout.height), cairo_surface_destroy);
  const Context context(cairo_create(surface.get()), cairo_destroy);
  cairo_t* cr = context.get();
  cairo_set_source_rgb(cr, 1, 1, 1);
  cairo_paint(cr);
  PaintMap(surface.get(), dem, layer, legend, layout.scale);

  // Paths: translucent blue lines, drawn once for the run (MapPaths).
  auto pixel = [&](const Eigen::Vector2d& p) { return PixelOf(g, layout, p); };
  cairo_rectangle(cr, 0, 0, layout.map_width, layout.map_height);
  cairo_clip(cr);
  if (paths.layer()) {
    cairo_set_source_surface(cr, paths.layer()->surface.get(), 0, 0);
    cairo_paint(cr);
  }
  // Evaluation lines: black over a white halo, named at their first vertex.
  for (const MapLine& line : lines) {
    if (line.xy_m.size() < 2) continue;
    for (const auto& [width, grey] : {std::pair{5.0, 1.0}, std::pair{2.5, 0.0}}) {
      cairo_set_source_rgb(cr, grey, grey, grey);
      cairo_set_line_width(cr, width);
      for (std::size_t k = 0; k < line.xy_m.size(); ++k) {
        const Eigen::Vector2d p = pixel(line.xy_m[k]);
        if (k == 0)
          cairo_move_to(cr, p.x(), p.y());
        else
          cairo_line_to(cr, p.x(), p.y());
      }
      cairo_stroke(cr);
    }
    const Eigen::Vector2d at = pixel(line.xy_m.front());
    cairo_select_font_face(cr, "DejaVu Sans", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_BOLD);
    cairo_set_font_size(cr, 13);
    cairo_move_to(cr, at.x() + 4, at.y() - 6);
    cairo_text_path(cr, line.name.c_str());
    cairo_set_source_rgb(cr, 1, 1, 1);
    cairo_set_line_width(cr, 3);
    cairo_stroke_preserve(cr);
    cairo_set_source_rgb(cr, 0, 0, 0);
    cairo_fill(cr);
  }
  for (const MapMarker& m : markers) {
    const Eigen::Vector2d centre = pixel(m.xy_m);
    SetColour(cr, m.rgb);
    cairo_arc(cr, centre.x(), centre.y(), m.radius_px, 0, 2 * std::numbers::pi);
    cairo_fill(cr);
  }
  DrawScaleBar(cr, g, layout);
  DrawNorthArrow(cr, layout);
  cairo_reset_clip(cr);
  DrawLegend(cr, layer, legend, paths.size(), markers, lines.size(), layout);

  return SurfacePng(surface.get());
}

void WriteQuickLookPng(const std::string& path, const Heightfield& dem,
                       const ensemble::RasterLayer* layer,
                       const std::vector<std::vector<Eigen::Vector2d>>& paths,
                       const std::vector<MapMarker>& markers, const std::vector<MapLine>& lines) {
  WriteFileAtomically(path, QuickLookPng(dem, layer, paths, markers, lines));
}

}  // namespace talus::io
