#include "io/quicklook.hpp"

#include <gdal_priv.h>
#include <gtest/gtest.h>

#include "common/atomic_file.hpp"
#include "test_files.hpp"

namespace talus::io {
namespace {

TEST(QuickLook, PicksTheLayerInOrderOfPreference) {
  std::vector<ensemble::RasterLayer> layers(3);
  layers[0].name = "speed_max";
  layers[1].name = "passages";
  layers[2].name = "energy_max";
  EXPECT_EQ(QuickLookLayer(layers)->name, "energy_max");
  layers[1].name = "reach_probability";
  EXPECT_EQ(QuickLookLayer(layers)->name, "reach_probability");
  EXPECT_EQ(QuickLookLayer({}), nullptr);
}

// Reads one pixel of band 1..3 of an open PNG.
unsigned char Pixel(GDALDataset* png, int band, int x, int y) {
  unsigned char value = 0;
  EXPECT_EQ(png->GetRasterBand(band)->RasterIO(GF_Read, x, y, 1, 1, &value, 1, 1, GDT_Byte, 0, 0),
            CE_None);
  return value;
}

TEST(QuickLook, WritesAnRgbPngNorthUpWithALegendBesideTheMap) {
  const auto dir = testing::FreshDir("png");
  const Heightfield dem = MakePlaneHeightfield({30, 20, 10, 20, 1});
  ensemble::RasterLayer reach{"reach_probability", "1", std::vector<float>(dem.z_m.size(), 0.0f)};
  reach.values[0] = 1.0f;  // south-west corner cell
  const auto path = (dir / "quicklook.png").string();
  WriteQuickLookPng(path, dem, &reach, {{{2, 0}, {25, 5}}});
  RegisterGdal();
  GDALDataset* png = static_cast<GDALDataset*>(GDALOpen(path.c_str(), GA_ReadOnly));
  ASSERT_NE(png, nullptr);
  EXPECT_EQ(png->GetRasterCount(), 3);
  const QuickLookLayout layout = QuickLookLayoutOf(dem.grid);
  EXPECT_EQ(png->GetRasterXSize(), layout.width);
  EXPECT_EQ(png->GetRasterYSize(), layout.height);
  EXPECT_GT(layout.width, layout.map_width + 200);  // room for the legend
  // The south-west cell is at the map's bottom left, in the class 30 - 100 % (dark red: red well
  // above blue).
  const int y = layout.map_height - 1;
  EXPECT_GT(Pixel(png, 1, 0, y), Pixel(png, 3, 0, y) + 40);
  // Cells no rock passed keep the grey hillshade (red == blue).
  EXPECT_EQ(Pixel(png, 1, layout.map_width / 2, layout.map_height / 2),
            Pixel(png, 3, layout.map_width / 2, layout.map_height / 2));
  // The legend panel holds text and swatches: many dark and many coloured pixels, which a blank
  // panel would not.
  int dark = 0, coloured = 0;
  for (int yy = 0; yy < layout.height; ++yy)
    for (int xx = layout.map_width; xx < layout.width; xx += 2) {
      const int r = Pixel(png, 1, xx, yy), b = Pixel(png, 3, xx, yy);
      dark += r < 100 && b < 100;
      coloured += r > b + 60;
    }
  EXPECT_GT(dark, 200);
  EXPECT_GT(coloured, 200);
  GDALClose(png);
}

TEST(QuickLook, ScaleBarLengthsAreOneTwoOrFiveTimesAPowerOfTen) {
  EXPECT_DOUBLE_EQ(ScaleBarLength(240), 200);
  EXPECT_DOUBLE_EQ(ScaleBarLength(1000), 1000);
  EXPECT_DOUBLE_EQ(ScaleBarLength(999), 500);
  EXPECT_DOUBLE_EQ(ScaleBarLength(0.7), 0.5);
  EXPECT_DOUBLE_EQ(ScaleBarLength(0), 0);
}

// An evaluation line is drawn black across the map (over the grey hillshade, where no rock passed).
TEST(QuickLook, DrawsEvaluationLinesInBlack) {
  const auto dir = testing::FreshDir("lines");
  const Heightfield dem = MakePlaneHeightfield({30, 20, 10, 20, 1});
  const QuickLookLayout layout = QuickLookLayoutOf(dem.grid);
  // Across the map at x = 15 m: pixel column (15 + 0.5) cells from the map's western edge.
  const int column = static_cast<int>(15.5 * layout.scale);
  const auto path = (dir / "quicklook.png").string();
  RegisterGdal();
  for (const bool with_line : {false, true}) {
    std::vector<MapLine> lines;
    if (with_line) lines.push_back({"barrier", {{15, -9}, {15, 9}}});
    WriteQuickLookPng(path, dem, nullptr, {}, {}, lines);
    GDALDataset* png = static_cast<GDALDataset*>(GDALOpen(path.c_str(), GA_ReadOnly));
    ASSERT_NE(png, nullptr);
    const int y = layout.map_height / 2;
    EXPECT_EQ(Pixel(png, 1, column, y) < 30, with_line) << int(Pixel(png, 1, column, y));
    GDALClose(png);
  }
}

// Paths are drawn in translucent blue along their vertices: those crowded within a pixel of the
// last one drawn are skipped, the others are not (a path that turns stays turned).
TEST(QuickLook, DrawsPathsInBlueAlongTheirVertices) {
  const auto dir = testing::FreshDir("paths");
  const Heightfield dem = MakePlaneHeightfield({30, 20, 10, 20, 1});
  const QuickLookLayout layout = QuickLookLayoutOf(dem.grid);
  // A rock creeping 1 cm in 500 samples (a hundredth of a pixel each), then north 8 m in steps of
  // 1 m, then east 20 m in one.
  std::vector<Eigen::Vector2d> path;
  for (int k = 0; k <= 500; ++k) path.emplace_back(3 + 0.01 * k / 500, 0);
  for (int k = 1; k <= 8; ++k) path.emplace_back(3, k);
  path.emplace_back(23, 8);
  const MapPaths paths(dem.grid, {path});
  EXPECT_EQ(paths.size(), 1u);
  // The pixel of (x, y) m, where the map places cell centres.
  const auto column = [&](double x) {
    return static_cast<int>((x - dem.grid.x0_m + 0.5) * layout.scale);
  };
  const auto row = [&](double y) {
    return static_cast<int>((dem.grid.y_max_m() + 0.5 - y) * layout.scale);
  };
  const auto file = (dir / "quicklook.png").string();
  RegisterGdal();
  for (const bool with_path : {false, true}) {
    WriteFileAtomically(file, QuickLookPngOf(dem, nullptr, with_path ? paths : MapPaths(), {}, {}));
    GDALDataset* png = static_cast<GDALDataset*>(GDALOpen(file.c_str(), GA_ReadOnly));
    ASSERT_NE(png, nullptr);
    const auto blue = [&](double x, double y) {
      return Pixel(png, 3, column(x), row(y)) > Pixel(png, 1, column(x), row(y)) + 30;
    };
    EXPECT_EQ(blue(3, 0.5), with_path);  // the creep's end, heading north
    EXPECT_EQ(blue(3, 5), with_path);
    EXPECT_EQ(blue(20, 8), with_path);
    EXPECT_FALSE(blue(13, 4));  // the corner is not cut
    GDALClose(png);
  }
}

}  // namespace
}  // namespace talus::io
