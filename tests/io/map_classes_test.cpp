// The colour classes every map of a run shares (io/map_classes.hpp): absolute classes with the
// hazard limits for energy, the same whatever else a raster holds, and the rocks' energy classes
// (EnergyLegend) those of the energy_max raster.

#include "io/map_classes.hpp"

#include <gtest/gtest.h>

#include <string>
#include <utility>

namespace talus::io {
namespace {

TEST(MapClasses, EnergyClassesAreAbsoluteWithTheHazardLimitsAt30And300Kilojoules) {
  const ensemble::RasterLayer energy{"energy_max", "J", {}};
  const QuickLookLegend legend = LegendOf(energy);
  EXPECT_EQ(legend.ClassOf(0), -1);      // no rock: not coloured
  EXPECT_EQ(legend.ClassOf(29.9e3), 0);  // below 30 kJ
  EXPECT_EQ(legend.ClassOf(30e3), 1);
  EXPECT_EQ(legend.ClassOf(299e3), 1);
  EXPECT_EQ(legend.ClassOf(300e3), 2);
  EXPECT_EQ(legend.ClassOf(1e9), static_cast<int>(legend.classes.size()) - 1);
  EXPECT_NE(legend.title.find("kJ"), std::string::npos);
  EXPECT_NE(legend.title.find("largest"), std::string::npos);
  // One rock in a hundred is 1 %, although the float raster holds 0.01f < 0.01.
  const ensemble::RasterLayer reach{"reach_probability", "1", {}};
  EXPECT_EQ(LegendOf(reach).ClassOf(1.0f / 100.0f), 1);
  // The same value has the same class whatever else the raster holds.
  const ensemble::RasterLayer speed{"speed_p95", "m/s", {1, 50}};
  EXPECT_EQ(LegendOf(speed).ClassOf(12), 2);  // 10 - 20 m/s
  EXPECT_NE(LegendOf(speed).title.find("95th percentile"), std::string::npos);
  for (auto [name, ordinal] : {std::pair{"energy_p1", "1st"},
                               {"energy_p22", "22nd"},
                               {"energy_p13", "13th"},
                               {"energy_p3", "3rd"}})
    EXPECT_NE(LegendOf({name, "J", {}}).title.find(std::string(", ") + ordinal + " percentile"),
              std::string::npos)
        << LegendOf({name, "J", {}}).title;
}

TEST(MapClasses, TheRocksEnergyClassesAreThoseOfTheLargestEnergyRaster) {
  const QuickLookLegend rocks = EnergyLegend(), raster = LegendOf({"energy_max", "J", {}});
  EXPECT_EQ(rocks.title, raster.title);
  ASSERT_EQ(rocks.classes.size(), raster.classes.size());
  for (std::size_t k = 0; k < rocks.classes.size(); ++k) {
    EXPECT_EQ(rocks.classes[k].lower, raster.classes[k].lower);
    EXPECT_EQ(rocks.classes[k].label, raster.classes[k].label);
    EXPECT_EQ(rocks.classes[k].rgb, raster.classes[k].rgb);
  }
}

}  // namespace
}  // namespace talus::io
