// Scene::IsValid (solver/scene.hpp): a scene built in a few lines is valid, and each part that is
// not names itself ("terrain: ", "ground: ", "rock: ", "solver: ") and the reason, including the
// cross-checks between the terrain's ground indices and the ground table.

#include "solver/scene.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "solver/shapes.hpp"

namespace talus {
namespace {

// A flat 3 x 3-node terrain on ground index `default_ground` and a 1 m cube of granite.
Scene SmallScene(int default_ground = 0) {
  Heightfield h;
  h.grid = {.nx = 3, .ny = 3, .x0_m = 0, .y0_m = 0, .dx_m = 1, .dy_m = 1};
  h.z_m.assign(9, 0.0);
  Scene scene;
  scene.terrain = Terrain(std::move(h), default_ground);
  scene.rock = MakeRockShape(MakeBox(1, 1, 1), 2700);
  return scene;
}

GroundGrid Grid(std::uint8_t value) {
  GroundGrid g;
  g.grid = {.nx = 2, .ny = 2, .x0_m = 0, .y0_m = 0, .dx_m = 2, .dy_m = 2};
  g.index.assign(4, value);
  return g;
}

// True when `why` starts with `prefix` and contains `detail`.
::testing::AssertionResult Says(const std::string& why, const std::string& prefix,
                                const std::string& detail) {
  if (why.rfind(prefix, 0) == 0 && why.find(detail) != std::string::npos)
    return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "'" << why << "' is not '" << prefix << "...'" << detail;
}

TEST(Scene, ASmallSceneIsValidAndNullWhyIsAllowed) {
  std::string why;
  EXPECT_TRUE(SmallScene().IsValid(&why)) << why;
  EXPECT_TRUE(SmallScene().IsValid(nullptr));
  Scene bad = SmallScene();
  bad.options.dt_s = -1;
  EXPECT_FALSE(bad.IsValid(nullptr));
}

TEST(Scene, EachInvalidPartIsNamed) {
  std::string why;
  Scene s;  // a default terrain has no grid
  s.rock = SmallScene().rock;
  EXPECT_FALSE(s.IsValid(&why));
  EXPECT_TRUE(Says(why, "terrain: ", "at least 2 x 2"));

  s = SmallScene();
  GroundCategory broken{"broken", 42, {}};
  broken.params.kappa_1_m = -1;
  s.ground.Set(broken);
  EXPECT_FALSE(s.IsValid(&why));
  EXPECT_TRUE(Says(why, "ground: ", "'broken'"));
  EXPECT_TRUE(Says(why, "ground: ", "kappa = -1"));

  s = SmallScene();
  s.rock.mass_kg = 0;
  EXPECT_FALSE(s.IsValid(&why));
  EXPECT_TRUE(Says(why, "rock: ", "mass"));

  s = SmallScene();
  s.options.max_iterations = 0;
  EXPECT_FALSE(s.IsValid(&why));
  EXPECT_TRUE(Says(why, "solver: ", "max_iterations = 0"));
}

// The terrain's default ground index and every index of its ground grid must be rows of the
// ground table (the built-in table has 8); kNoGround cells take the default and are allowed.
TEST(Scene, GroundIndicesOfTheTerrainMustBeInTheTable) {
  std::string why;
  const int rows = GroundTable::BuiltIn().size();
  ASSERT_EQ(rows, 8);
  EXPECT_TRUE(SmallScene(rows - 1).IsValid(&why)) << why;
  EXPECT_FALSE(SmallScene(rows).IsValid(&why));
  EXPECT_TRUE(Says(why, "terrain: ", "default ground index 8 is not in the table"));
  EXPECT_FALSE(SmallScene(-1).IsValid(&why));
  EXPECT_TRUE(Says(why, "terrain: ", "default ground index -1"));

  Scene s = SmallScene();
  s.terrain.SetGroundGrid(Grid(GroundGrid::kNoGround));
  EXPECT_TRUE(s.IsValid(&why)) << why;
  s.terrain.SetGroundGrid(Grid(static_cast<std::uint8_t>(rows - 1)));
  EXPECT_TRUE(s.IsValid(&why)) << why;
  s.terrain.SetGroundGrid(Grid(static_cast<std::uint8_t>(rows)));
  EXPECT_FALSE(s.IsValid(&why));
  EXPECT_TRUE(Says(why, "terrain: ", "ground grid refers to category index 8 not in the table"));
  // A ninth category makes index 8 valid.
  s.ground.Set({"scree", 9, {}});
  EXPECT_TRUE(s.IsValid(&why)) << why;
}

// The parts are checked in order: terrain, ground, rock, solver; the first bad one is reported.
TEST(Scene, TheFirstInvalidPartIsReported) {
  std::string why;
  Scene s = SmallScene();
  s.options.dt_s = 0;
  s.rock.mass_kg = std::nan("");
  EXPECT_FALSE(s.IsValid(&why));
  EXPECT_TRUE(Says(why, "rock: ", ""));
  s.terrain = Terrain();
  EXPECT_FALSE(s.IsValid(&why));
  EXPECT_TRUE(Says(why, "terrain: ", ""));
}

}  // namespace
}  // namespace talus
