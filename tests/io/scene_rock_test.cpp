// [rock] of a scene file (io/scene_rock.cpp) through io::LoadScene: each built-in shape's mass
// from its dimensions and density against the solid's closed form, mass_kg setting the density,
// and the errors scene_file_test.cpp does not reach, each naming the file, line and key.

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

#include "common/error.hpp"
#include "io/scene_file.hpp"
#include "test_files.hpp"

namespace talus::io {
namespace {

constexpr double kPi = std::numbers::pi;

const std::string kHead = R"([terrain]
plane = { slope_deg = 30, slope_length_m = 40, runout_m = 20, width_m = 30, cell_m = 1 }

[release]
points = [[5, 0]]

[rock]
)";

SceneFile Load(const std::string& rock_table) {
  const auto dir = testing::FreshDir("scene");
  testing::WriteText(dir / "scene.toml", kHead + rock_table);
  return LoadScene((dir / "scene.toml").string());
}

std::string ErrorOf(const std::string& rock_table) {
  try {
    Load(rock_table);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

#define EXPECT_HAS(text, part) EXPECT_NE(std::string(text).find(part), std::string::npos) << (text)

// A box is exact: m = a b c rho. The smooth built-ins are inscribed polyhedra, so their volume is
// below the solid's and, at the built-in resolution (icosphere of 2 subdivisions, 3.4 % short;
// cylinder of 24 segments, 1.1 % short), within 4 % of it: sphere 4/3 pi r^3, ellipsoid
// pi a b c / 6, cylinder pi (d/2)^2 h.
TEST(SceneRock, BuiltInShapesHaveTheMassOfTheirSolids) {
  const double rho = 2600;
  EXPECT_NEAR(Load("shape = { box = [0.5, 0.4, 0.3] }\ndensity_kg_m3 = 2600\n").scene.rock.mass_kg,
              0.5 * 0.4 * 0.3 * rho, 1e-9);
  struct Smooth {
    const char* shape;
    double volume;
  };
  for (const Smooth& s : {Smooth{"sphere = 0.3", 4.0 / 3 * kPi * 0.027},
                          Smooth{"ellipsoid = [0.8, 0.5, 0.4]", kPi * 0.8 * 0.5 * 0.4 / 6},
                          Smooth{"cylinder = [0.6, 1.0]", kPi * 0.09 * 1.0}}) {
    const SceneFile f = Load(std::string("shape = { ") + s.shape + " }\ndensity_kg_m3 = 2600\n");
    EXPECT_LT(f.scene.rock.volume_m3, s.volume) << s.shape;
    EXPECT_GT(f.scene.rock.volume_m3, 0.96 * s.volume) << s.shape;
    EXPECT_NEAR(f.scene.rock.mass_kg, rho * f.scene.rock.volume_m3, 1e-9) << s.shape;
  }
}

// With the dimensions fixing the volume, mass_kg sets the density: the mass is the one given and
// the inertia scales with it (a box's I_zz = m (a^2 + b^2) / 12 about its largest-moment axis).
TEST(SceneRock, MassKgOfABuiltInSetsItsDensity) {
  const SceneFile f = Load("shape = { box = [1.0, 0.5, 0.2] }\nmass_kg = 300\n");
  EXPECT_DOUBLE_EQ(f.scene.rock.mass_kg, 300);
  EXPECT_NEAR(f.scene.rock.volume_m3, 0.1, 1e-12);
  EXPECT_NEAR(f.scene.rock.inertia_kg_m2.maxCoeff(), 300 * (1.0 + 0.25) / 12, 1e-9);
  EXPECT_NEAR(f.scene.rock.inertia_kg_m2.minCoeff(), 300 * (0.25 + 0.04) / 12, 1e-9);
}

TEST(SceneRock, ErrorsNameTheFileLineAndKey) {
  EXPECT_HAS(ErrorOf("density_kg_m3 = 2600\n"),
             "scene.toml:7: rock.shape: missing: a point cloud file or a built-in such as "
             "{ box = [1, 1, 1] }");
  EXPECT_HAS(ErrorOf("shape = 5\n"),
             "scene.toml:8: rock.shape: expected a file name or a built-in such as");
  EXPECT_HAS(ErrorOf("shape = \"rock.xyz\"\nvolume_m3 = 0.5\nmass_kg = 1300\n"),
             "scene.toml:10: rock.mass_kg: give volume_m3 or mass_kg, not both");
  EXPECT_HAS(ErrorOf("shape = { box = [1, 1, 1], size_m = [1, 1, 1] }\n"),
             "scene.toml:8: rock.shape.size_m: only an eota shape takes a size");
  EXPECT_HAS(ErrorOf("shape = { box = [1, 1, 1] }\nshape_per_rock = true\n"),
             "scene.toml:9: rock.shape_per_rock: only a built-in rock shape has a shape of its own "
             "per rock");
  EXPECT_HAS(ErrorOf("shape = { box = [1, 1, 1], sphere = 1 }\n"),
             "rock.shape: give exactly one of box, ellipsoid or rock");
  EXPECT_HAS(ErrorOf("shape = { cylinder = [1, 0] }\n"),
             "rock.shape.cylinder: dimensions must be > 0");
  EXPECT_HAS(ErrorOf("shape = { sphere = -1 }\n"), "rock.shape.sphere: ");
  EXPECT_HAS(ErrorOf("shape = { eota = \"331\" }\n"),
             "rock.shape.eota: '331': expected \"111\" or \"221\"");
  EXPECT_HAS(ErrorOf("shape = { box = [1, 1, 1] }\nmax_vertices = 3\n"),
             "rock.max_vertices: 3 must be 0 (no simplification) or in 4 .. 100000");
  EXPECT_HAS(ErrorOf("shape = { box = [1, 1, 1] }\nvolume_m3 = 2\n"),
             "rock.volume_m3: the dimensions of the shape fix its volume");
}

}  // namespace
}  // namespace talus::io
