#include "scenes/scenes.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

#include "solver/shapes.hpp"

namespace talus::scenes {
namespace {

double HeightAt(const Scene& scene, double x, double y) {
  double h = 0;
  EXPECT_TRUE(scene.terrain.Height(x, y, &h)) << x << ", " << y;
  return h;
}

// The EOTA221 block of the Chant Sura experiments (Caviezel et al. 2019): 780 kg, 0.93 x 0.93 x
// 0.47 m, density 2500 kg/m^3.
TEST(Eota221, HasThePublishedMassAndDimensions) {
  const RockShape rock = Eota221();
  std::string why;
  ASSERT_TRUE(rock.IsValid(&why)) << why;
  EXPECT_NEAR(rock.mass_kg, 780, 1e-6);
  EXPECT_NEAR(rock.volume_m3, 780.0 / 2500, 1e-9);
  EXPECT_NEAR(rock.length_m, 0.93, 1e-9);
  EXPECT_NEAR(rock.thickness_m, 0.47, 1e-9);
  // Platy: the largest principal moment is about the short axis, the two others equal (the block
  // is square in plan).
  EXPECT_LT(rock.inertia_kg_m2[0], rock.inertia_kg_m2[2]);
  EXPECT_NEAR(rock.inertia_kg_m2[0], rock.inertia_kg_m2[1], 1e-9 * rock.inertia_kg_m2[2]);
  // Bevelled: less than the full box, whose moment about the short axis is m (a^2 + a^2) / 12 at
  // the box's own mass.
  const double box_mass = 2500 * 0.93 * 0.93 * 0.47;
  EXPECT_LT(rock.mass_kg, box_mass);
  EXPECT_LT(rock.inertia_kg_m2[2], box_mass * 2 * 0.93 * 0.93 / 12);
}

TEST(Ramp40, IsAValidFortyDegreeSlopeWithAFlatRunoutOnMediumHardGround) {
  const Scene ramp = Ramp40();
  std::string why;
  ASSERT_TRUE(ramp.IsValid(&why)) << why;
  EXPECT_EQ(ramp.terrain.default_ground(), ramp.ground.IndexOfName("medium_hard"));
  const double tan40 = std::tan(40 * std::numbers::pi / 180);
  EXPECT_NEAR(HeightAt(ramp, 10, 0) - HeightAt(ramp, 30, 0), 20 * tan40, 1e-9);
  EXPECT_NEAR(HeightAt(ramp, 190, 20) - HeightAt(ramp, 198, 20), 8 * tan40, 1e-9);
  EXPECT_NEAR(HeightAt(ramp, 250, 0), HeightAt(ramp, 340, -40), 1e-9);  // the runout is flat
  EXPECT_NEAR(ramp.rock.mass_kg, Eota221().mass_kg, 0);
  EXPECT_EQ(ramp.options.dt_s, SolverOptions{}.dt_s);
}

TEST(Ramp40Release, StartsOneMetreAboveTheGroundAtTenMetresAtRest) {
  const Scene ramp = Ramp40();
  for (std::uint64_t rock = 0; rock < 5; ++rock) {
    const RockState s = Ramp40Release(ramp, 7, rock);
    EXPECT_NEAR(s.position_m.x(), 10, 1e-12);
    EXPECT_NEAR(s.position_m.y(), 0, 1e-12);
    // The centre of mass is 1 m above the ground, or higher when a vertex had to be raised.
    EXPECT_GE(s.position_m.z() - HeightAt(ramp, 10, 0), 1 - 1e-12);
    EXPECT_EQ(s.velocity_m_s, Eigen::Vector3d::Zero());
    EXPECT_EQ(s.angular_velocity_rad_s, Eigen::Vector3d::Zero());
    EXPECT_NEAR(s.orientation.norm(), 1, 1e-12);
  }
}

TEST(Ramp40Release, IsTheSameRockOfTheSpecWhateverItsSizeAndDiffersBetweenRocksAndSeeds) {
  const Scene ramp = Ramp40();
  const RockState a = Ramp40Release(ramp, 7, 3);
  const RockState b = ensemble::Release(ramp, Ramp40ReleaseSpec(7, 100), 3).start;
  EXPECT_EQ(a.orientation.coeffs(), b.orientation.coeffs());
  EXPECT_EQ(a.position_m, b.position_m);
  EXPECT_NE(a.orientation.coeffs(), Ramp40Release(ramp, 7, 4).orientation.coeffs());
  EXPECT_NE(a.orientation.coeffs(), Ramp40Release(ramp, 8, 3).orientation.coeffs());
}

TEST(Incline, HasTheSlopeAndOneGroundOfTheGivenParameters) {
  GroundParams ground;
  ground.mu_min = 0.42;
  ground.mu_max = 1.7;
  const RockShape rock = MakeRockShape(MakeBox(0.5, 0.4, 0.3), 2000);
  const Scene incline = Incline(25, rock, ground, 40, 1);
  std::string why;
  ASSERT_TRUE(incline.IsValid(&why)) << why;
  const int test = incline.ground.IndexOfName("test");
  ASSERT_GE(test, 0);
  EXPECT_EQ(incline.terrain.default_ground(), test);
  EXPECT_EQ(incline.terrain.GroundAt(20, 0), test);
  EXPECT_EQ(incline.ground.params(test).mu_min, 0.42);
  EXPECT_EQ(incline.ground.params(test).mu_max, 1.7);
  EXPECT_NEAR(HeightAt(incline, 5, 0) - HeightAt(incline, 35, 10),
              30 * std::tan(25 * std::numbers::pi / 180), 1e-9);
  EXPECT_EQ(incline.rock.mass_kg, rock.mass_kg);
  // Flat: every point at one height.
  const Scene flat = Incline(0, rock, ground, 40, 1);
  EXPECT_NEAR(HeightAt(flat, 1, -19), HeightAt(flat, 39, 19), 1e-12);
}

}  // namespace
}  // namespace talus::scenes
