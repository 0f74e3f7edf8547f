#include "io/rock_input.hpp"

#include <gtest/gtest.h>

#include "common/error.hpp"
#include "io/scene_file.hpp"
#include "test_files.hpp"

namespace talus::io {
namespace {

TEST(BuildRock, BuiltInsScaleToMassOrVolume) {
  RockInput box;
  box.builtin = "box";
  box.dimensions_m = {1, 2, 3};
  box.density_kg_m3 = 2000;
  EXPECT_NEAR(BuildRock(box).mass_kg, 12000, 1e-6);
  box.mass_kg = 1000;
  EXPECT_NEAR(BuildRock(box).volume_m3, 0.5, 1e-9);
  RockInput eota;
  eota.builtin = "eota221";
  eota.dimensions_m = {0.93, 0.93, 0.47};
  eota.density_kg_m3 = 2500;
  eota.mass_kg = 780;
  std::string report;
  const RockShape rock = BuildRock(eota, &report);
  EXPECT_NEAR(rock.mass_kg, 780, 1e-6);
  EXPECT_EQ(rock.vertices_m.size(), 24u);
  EXPECT_NE(report.find("eota221"), std::string::npos) << report;
}

// Point cloud files go through the pointclouds module: the hull of the points is the rock.
TEST(BuildRock, PointCloudFileFromAScene) {
  const auto dir = testing::FreshDir("cloud");
  std::string xyz;
  for (int k = 0; k < 8; ++k)
    xyz += std::to_string(k & 1 ? 0.5 : -0.5) + " " + std::to_string(k & 2 ? 0.25 : -0.25) + " " +
           std::to_string(k & 4 ? 0.1 : -0.1) + "\n";
  xyz += "0 0 0\n0.1 0.1 0\n";  // inside the hull
  testing::WriteText(dir / "block.xyz", xyz);
  testing::WriteText(dir / "scene.toml",
                     "[terrain]\nplane = {}\n[rock]\nshape = \"block.xyz\"\ndensity_kg_m3 = 2000\n"
                     "[release]\npoints = [[10, 0]]\n");
  const SceneFile s = LoadScene((dir / "scene.toml").string());
  EXPECT_NEAR(s.scene.rock.mass_kg, 1.0 * 0.5 * 0.2 * 2000, 1e-6);
  EXPECT_EQ(s.scene.rock.vertices_m.size(), 8u);
  EXPECT_EQ(s.inputs.size(), 2u);  // the scene and the point cloud
}

TEST(BuildRock, BadSpecsAreInputErrors) {
  RockInput unknown;
  unknown.builtin = "pyramid";
  unknown.dimensions_m = {1, 1, 1};
  EXPECT_THROW(BuildRock(unknown), InputError);
}

}  // namespace
}  // namespace talus::io
