#include "io/quicklook.hpp"

#include <gdal_priv.h>
#include <gtest/gtest.h>

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

TEST(QuickLook, WritesAnRgbPngNorthUp) {
  const auto dir = testing::FreshDir("png");
  const Heightfield dem = MakePlaneHeightfield({30, 20, 10, 20, 1});
  ensemble::RasterLayer reach{"reach_probability", "1", std::vector<float>(dem.z_m.size(), 0.0f),
                              false};
  reach.values[0] = 1.0f;  // south-west corner cell
  const auto path = (dir / "quicklook.png").string();
  WriteQuickLookPng(path, dem, &reach, {{{2, 0}, {25, 5}}});
  RegisterGdal();
  GDALDataset* png = static_cast<GDALDataset*>(GDALOpen(path.c_str(), GA_ReadOnly));
  ASSERT_NE(png, nullptr);
  EXPECT_EQ(png->GetRasterCount(), 3);
  const int scale = png->GetRasterXSize() / dem.grid.nx;
  EXPECT_EQ(png->GetRasterYSize(), dem.grid.ny * scale);
  // The south-west cell is at the bottom left, in the ramp's dark red (red well above blue).
  unsigned char red = 0, blue = 0;
  const int y = png->GetRasterYSize() - 1;
  EXPECT_EQ(png->GetRasterBand(1)->RasterIO(GF_Read, 0, y, 1, 1, &red, 1, 1, GDT_Byte, 0, 0),
            CE_None);
  EXPECT_EQ(png->GetRasterBand(3)->RasterIO(GF_Read, 0, y, 1, 1, &blue, 1, 1, GDT_Byte, 0, 0),
            CE_None);
  EXPECT_GT(red, blue + 40);
  GDALClose(png);
}

}  // namespace
}  // namespace talus::io
