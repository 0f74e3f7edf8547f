#include "io/scene_file.hpp"

#include <gtest/gtest.h>
#include <ogr_spatialref.h>

#include <chrono>
#include <cmath>
#include <fstream>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>

#include "common/error.hpp"
#include "io/summary.hpp"
#include "test_files.hpp"
#include "tests/portable_random.hpp"

namespace talus::io {
namespace {

const char* kPlaneScene = R"([terrain]
plane = { slope_deg = 35, slope_length_m = 40, runout_m = 20, width_m = 30, cell_m = 1 }
default_ground = "hard"

[rock]
shape = { box = [0.5, 0.4, 0.3] }
density_kg_m3 = 2600

[release]
points = [[5, 0], [6, 2]]
lines = [[[3, -5], [3, 5]]]
polygons = [[[8, -2], [10, -2], [10, 2], [8, 2]]]
rocks = 7
height_m = 1.5
orientation = [1, 0, 0, 0]
velocity_m_s = [1, 0, 0]
angular_velocity_rad_s = [0, 0, 1]
seed = 42

[solver]
dt_s = 0.004
max_time_s = 20

[output]
trajectories = true
trajectory_interval_s = 0.1
rasters = ["speed", "reach_probability"]
)";

std::string Replace(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return text.replace(at, from.size(), to);
}

// Loads `text` as scene.toml and returns the error message ("" when it loads).
std::string ErrorOf(const std::string& text, const std::filesystem::path& dir) {
  testing::WriteText(dir / "scene.toml", text);
  try {
    LoadScene((dir / "scene.toml").string());
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

#define EXPECT_HAS(text, part) EXPECT_NE(std::string(text).find(part), std::string::npos) << (text)

TEST(LoadScene, PlaneSceneWithEveryRelease) {
  const auto dir = testing::FreshDir("plane");
  testing::WriteText(dir / "scene.toml", kPlaneScene);
  const SceneFile s = LoadScene((dir / "scene.toml").string());
  std::string why;
  EXPECT_TRUE(s.scene.IsValid(&why)) << why;
  EXPECT_EQ(s.scene.terrain.default_ground(), s.scene.ground.IndexOfName("hard"));
  EXPECT_EQ(s.scene.terrain.heights().grid.nx, 61);
  EXPECT_NEAR(s.scene.rock.mass_kg, 0.5 * 0.4 * 0.3 * 2600, 1e-9);
  ASSERT_EQ(s.release.releases.size(), 4u);
  EXPECT_EQ(s.release.releases[2].kind, ensemble::ReleaseGeometry::Kind::kLine);
  EXPECT_EQ(s.release.releases[3].kind, ensemble::ReleaseGeometry::Kind::kPolygon);
  EXPECT_EQ(s.release.total_rocks(), 28);
  EXPECT_EQ(s.release.seed, 42u);
  EXPECT_DOUBLE_EQ(s.release.height_m, 1.5);
  ASSERT_TRUE(s.release.orientation.has_value());
  EXPECT_DOUBLE_EQ(s.release.velocity_m_s.x(), 1);
  EXPECT_DOUBLE_EQ(s.scene.options.dt_s, 0.004);
  EXPECT_TRUE(s.output.trajectories);
  const auto request = s.output.Request(s.scene.terrain.heights().grid);
  EXPECT_TRUE(request.speed && request.reach_probability);
  EXPECT_FALSE(request.energy || request.passages || request.deposits || request.jump_height);
  EXPECT_TRUE(s.crs_wkt.empty());
  EXPECT_EQ(s.inputs_hash.size(), 64u);  // SHA-256, hex
}

TEST(LoadScene, MinimalSceneUsesDefaults) {
  const auto dir = testing::FreshDir("minimal");
  testing::WriteText(
      dir / "scene.toml",
      "[terrain]\nplane = {}\n[rock]\nshape = { eota = \"221\" }\n[release]\npoints = [[10, 0]]\n");
  const SceneFile s = LoadScene((dir / "scene.toml").string());
  EXPECT_EQ(s.scene.terrain.default_ground(), s.scene.ground.IndexOfName("medium"));
  EXPECT_NEAR(s.scene.rock.volume_m3, 1.0, 1e-6);
  EXPECT_FALSE(s.release.orientation.has_value());
  EXPECT_FALSE(s.output.trajectories);
  EXPECT_TRUE(s.output.rasters.empty());
  EXPECT_FALSE(s.output.Request(s.scene.terrain.heights().grid).any());
}

TEST(LoadScene, UnknownKeysAreErrorsWithDidYouMean) {
  const auto dir = testing::FreshDir("unknown");
  const std::string e1 = ErrorOf(Replace(kPlaneScene, "rocks = 7", "rock = 7"), dir);
  EXPECT_HAS(e1, "scene.toml:13: release.rock: unknown key (did you mean 'rocks'?)");
  const std::string e2 = ErrorOf(Replace(kPlaneScene, "[solver]", "[solvr]"), dir);
  EXPECT_HAS(e2, "solvr: unknown key (did you mean 'solver'?)");
  const std::string e3 = ErrorOf(Replace(kPlaneScene, "cell_m = 1", "cell = 1"), dir);
  EXPECT_HAS(e3, "terrain.plane.cell: unknown key (did you mean 'cell_m'?)");
  const std::string e4 = ErrorOf(Replace(kPlaneScene, "\"speed\",", "\"speeds\","), dir);
  EXPECT_HAS(e4,
             "output.rasters: unknown raster 'speeds' (did you mean 'speed'?); known: speed, "
             "energy, jump_height, passages, deposits, reach_probability");
  const std::string e5 = ErrorOf(Replace(kPlaneScene, "\"hard\"", "\"hrad\""), dir);
  EXPECT_HAS(e5, "terrain.default_ground: unknown ground category 'hrad' (did you mean 'hard'?)");
  const std::string e6 = ErrorOf(Replace(kPlaneScene, "seed = 42", "colour = \"red\""), dir);
  EXPECT_HAS(e6, "release.colour: unknown key");
  EXPECT_EQ(e6.find("did you mean"), std::string::npos) << e6;
}

TEST(LoadScene, NonPhysicalValuesNameKeyAndReason) {
  const auto dir = testing::FreshDir("values");
  EXPECT_HAS(ErrorOf(Replace(kPlaneScene, "density_kg_m3 = 2600", "density_kg_m3 = -1"), dir),
             "rock.density_kg_m3: -1 must be > 0");
  EXPECT_HAS(ErrorOf(Replace(kPlaneScene, "dt_s = 0.004", "dt_s = -0.1"), dir), "solver.dt_s");
  EXPECT_HAS(ErrorOf(Replace(kPlaneScene, "slope_deg = 35", "slope_deg = 95"), dir), "slope_deg");
  EXPECT_HAS(ErrorOf(Replace(kPlaneScene, "rocks = 7", "rocks = 0"), dir),
             "release.rocks: 0 must be >= 1");
  EXPECT_HAS(
      ErrorOf(Replace(kPlaneScene, "orientation = [1, 0, 0, 0]", "orientation = [2, 0, 0, 0]"),
              dir),
      "release.orientation: quaternion [w, x, y, z] has norm 2");
  EXPECT_HAS(ErrorOf(Replace(kPlaneScene, "height_m = 1.5", "height_m = \"high\""), dir),
             "release.height_m: expected a number");
  EXPECT_HAS(
      ErrorOf(Replace(kPlaneScene, "velocity_m_s = [1, 0, 0]", "velocity_m_s = [1, 0]"), dir),
      "release.velocity_m_s: expected a list of 3 numbers");
  EXPECT_HAS(ErrorOf(Replace(kPlaneScene, "box = [0.5, 0.4, 0.3]", "box = [0.5, 0, 0.3]"), dir),
             "rock.shape.box: dimensions must be > 0");
  EXPECT_HAS(ErrorOf(std::string(kPlaneScene) + "[ground.soft]\nmu_min = 3\n", dir),
             "ground.soft: mu_max");
  EXPECT_HAS(ErrorOf("[terrain\nplane = {}\n", dir), "scene.toml:1: TOML syntax error");
}

// A value that an options check rejects is reported on its key's line, not its table's header.
TEST(LoadScene, RejectedValuesGiveTheLineOfTheirKey) {
  const auto dir = testing::FreshDir("key_lines");
  EXPECT_HAS(ErrorOf(Replace(kPlaneScene, "dt_s = 0.004", "dt_s = -0.1"), dir),
             "scene.toml:21: solver.dt_s: dt_s = -0.1 violates 0 < dt_s <= 0.1 s");
  EXPECT_HAS(
      ErrorOf(Replace(kPlaneScene, "max_time_s = 20", "max_time_s = 20\nprox_alpha = 3"), dir),
      "scene.toml:23: solver.prox_alpha: prox_alpha = 3 violates 0 < prox_alpha < 2");
  EXPECT_HAS(ErrorOf(std::string(kPlaneScene) + "[ground.soft]\nmu_min = 0.5\nmu_max = 0.1\n", dir),
             "scene.toml:30: ground.soft.mu_max: mu_max = 0.1 violates");
  EXPECT_HAS(
      ErrorOf(Replace(kPlaneScene, "rocks = 7", "rocks = 900000000"), dir),
      "scene.toml:13: release.rocks: rocks = 900000000 per release x 4 releases is more than");
  EXPECT_HAS(ErrorOf(Replace(kPlaneScene, "runout_m = 20", "runout_m = -20"), dir),
             "scene.toml:2: terrain.plane.runout_m: runout_m = -20 must be >= 0");
}

TEST(LoadScene, ViscousReadingIsChosenByNameWithDidYouMean) {
  const auto dir = testing::FreshDir("viscous");
  testing::WriteText(dir / "scene.toml", kPlaneScene);
  EXPECT_EQ(LoadScene((dir / "scene.toml").string()).scene.options.viscous,
            ViscousReading::kContactFriction);  // the default
  testing::WriteText(dir / "scene.toml", Replace(kPlaneScene, "max_time_s = 20",
                                                 "max_time_s = 20\nviscous = \"centre_of_mass\""));
  EXPECT_EQ(LoadScene((dir / "scene.toml").string()).scene.options.viscous,
            ViscousReading::kCentreOfMass);
  EXPECT_HAS(ErrorOf(Replace(kPlaneScene, "max_time_s = 20",
                             "max_time_s = 20\nviscous = \"center_of_mass\""),
                     dir),
             "scene.toml:23: solver.viscous: unknown reading 'center_of_mass' (did you mean "
             "'centre_of_mass'?); known: centre_of_mass, contact_friction");
  EXPECT_HAS(ErrorOf(Replace(kPlaneScene, "max_time_s = 20", "max_time_s = 20\nviscous = 1"), dir),
             "solver.viscous: expected a string");
  EXPECT_HAS(ErrorOf(Replace(kPlaneScene, "max_time_s = 20", "max_time_s = 20\nviscus = 1"), dir),
             "solver.viscus: unknown key (did you mean 'viscous'?)");
}

TEST(LoadScene, DragLayerPerCategoryWithBounds) {
  const auto dir = testing::FreshDir("drag_layer");
  testing::WriteText(dir / "scene.toml",
                     std::string(kPlaneScene) +
                         "[ground.medium]\ndrag_height_m = 5\ndrag_translational = 0.3\n"
                         "drag_rotational = 0.2\n");
  const SceneFile s = LoadScene((dir / "scene.toml").string());
  const GroundParams& p = s.scene.ground.params(s.scene.ground.IndexOfName("medium"));
  EXPECT_EQ(p.drag_height_m, 5);
  EXPECT_EQ(p.drag_translational_1_s, 0.3);
  EXPECT_EQ(p.drag_rotational_1_s, 0.2);
  EXPECT_EQ(p.mu_min, 0.35);  // the built-in's other keys stay
  EXPECT_TRUE(s.scene.ground.AnyDragLayer());
  testing::WriteText(dir / "scene.toml", kPlaneScene);
  EXPECT_FALSE(LoadScene((dir / "scene.toml").string()).scene.ground.AnyDragLayer());  // off
  EXPECT_HAS(
      ErrorOf(std::string(kPlaneScene) + "[ground.medium]\ndrag_height_m = 500\n", dir),
      "ground.medium.drag_height_m: drag_height_m = 500 violates 0 <= drag_height_m <= 100 (m)");
  EXPECT_HAS(ErrorOf(std::string(kPlaneScene) + "[ground.medium]\ndrag_rotational = -1\n", dir),
             "drag_rotational = -1 violates");
  EXPECT_HAS(ErrorOf(std::string(kPlaneScene) + "[ground.medium]\ndrag_hight_m = 5\n", dir),
             "did you mean 'drag_height_m'?");
}

TEST(LoadScene, ScarringSoilPerCategoryWithItsParametersAndBounds) {
  const auto dir = testing::FreshDir("soil");
  testing::WriteText(dir / "scene.toml",
                     std::string(kPlaneScene) +
                         "[ground.medium]\nmodel = \"lu2019\"\nsoil_strength = 25\n"
                         "compaction_drag = 4\n");
  const SceneFile s = LoadScene((dir / "scene.toml").string());
  const GroundParams& p = s.scene.ground.params(s.scene.ground.IndexOfName("medium"));
  EXPECT_EQ(p.model, GroundModel::kLu2019);
  EXPECT_EQ(p.soil_strength_mn_m2, 25);
  EXPECT_EQ(p.compaction_drag, 4);
  EXPECT_EQ(p.fluid_drag, 1.0);           // the paper's C_f
  EXPECT_EQ(p.soil_density_kg_m3, 1700);  // and rho
  EXPECT_TRUE(s.scene.ground.AnySoil());
  EXPECT_EQ(s.scene.options.soil_drag, SoilDragPoint::kCentreOfMass);
  testing::WriteText(dir / "scene.toml", kPlaneScene);
  EXPECT_FALSE(LoadScene((dir / "scene.toml").string()).scene.ground.AnySoil());  // off
  EXPECT_HAS(ErrorOf(std::string(kPlaneScene) + "[ground.medium]\nmodel = \"lu2018\"\n", dir),
             "ground.medium.model: unknown ground model 'lu2018'; known: hard, lu2019");
  EXPECT_HAS(ErrorOf(std::string(kPlaneScene) + "[ground.medium]\nsoil_strength = 25\n", dir),
             "ground.medium.soil_strength: soil_strength acts only in a category with model = "
             "\"lu2019\"");
  EXPECT_HAS(
      ErrorOf(std::string(kPlaneScene) + "[ground.medium]\nmodel = \"lu2019\"\nsoil_strength = 0\n",
              dir),
      "soil_strength = 0 violates 0.1 <= soil_strength <= 1000 (MN/m^2)");
  EXPECT_HAS(ErrorOf(std::string(kPlaneScene) +
                         "[ground.medium]\nmodel = \"lu2019\"\ncompaction_drag = nan\n",
                     dir),
             "compaction_drag = nan violates");
  EXPECT_HAS(ErrorOf(std::string(kPlaneScene) + "[ground.medium]\nnu = 1e160\n", dir),
             "nu = 1e+160 violates 0 <= nu <= 10000 (1/s)");
  EXPECT_HAS(ErrorOf(Replace(kPlaneScene, "[solver]", "[solver]\nsoil_drag = \"centroid\""), dir),
             "solver.soil_drag: unknown drag point 'centroid'");
}

// Newton's impact law takes one coefficient (SolverOptions): tangential_restitution follows
// normal_restitution unless given, and a different one is refused with the reason.
TEST(LoadScene, RestitutionIsOneCoefficient) {
  const auto dir = testing::FreshDir("restitution");
  const auto with = [](const std::string& keys) {
    return Replace(kPlaneScene, "max_time_s = 20", "max_time_s = 20\n" + keys);
  };
  testing::WriteText(dir / "scene.toml", with("normal_restitution = 0.4"));
  const SolverOptions o = LoadScene((dir / "scene.toml").string()).scene.options;
  EXPECT_EQ(o.normal_restitution, 0.4);
  EXPECT_EQ(o.tangential_restitution, 0.4);
  testing::WriteText(dir / "scene.toml",
                     with("normal_restitution = 0.4\ntangential_restitution = 0.4"));
  EXPECT_EQ(LoadScene((dir / "scene.toml").string()).scene.options.tangential_restitution, 0.4);
  EXPECT_HAS(ErrorOf(with("normal_restitution = 1\ntangential_restitution = 0.5"), dir),
             "tangential_restitution = 0.5 violates tangential_restitution == normal_restitution "
             "(Newton's impact law adds energy for unequal coefficients");
  EXPECT_HAS(ErrorOf(with("normal_restitution = 1\ntangential_restitution = -1"), dir),
             "tangential_restitution = -1 violates 0 <= tangential_restitution <= 1");
  EXPECT_HAS(ErrorOf(with("tangential_restitution = 0.5"), dir),
             "tangential_restitution = 0.5 violates");
  // Newton's law keeps whole steps: impact_substeps' default gives way to a restitution, and a
  // scene that asks for both is refused by name.
  EXPECT_EQ(o.impact_substeps, 1);
  testing::WriteText(dir / "scene.toml", with(""));
  EXPECT_EQ(LoadScene((dir / "scene.toml").string()).scene.options.impact_substeps, 4);
  EXPECT_HAS(ErrorOf(with("normal_restitution = 0.4\nimpact_substeps = 4"), dir),
             "impact_substeps = 4 needs normal_restitution = 0 (Newton's law takes the begin "
             "velocities of a whole step; it is 0.4)");
  testing::WriteText(dir / "scene.toml", with("normal_restitution = 0.4\nimpact_substeps = 1"));
  EXPECT_EQ(LoadScene((dir / "scene.toml").string()).scene.options.impact_substeps, 1);
  // Nor does it hold contacts (SolverOptions::contact_hold).
  EXPECT_HAS(ErrorOf(with("normal_restitution = 0.4\ncontact_hold = \"held\""), dir),
             "contact_hold = \"held\" needs normal_restitution = 0 (Newton's law would rebound a "
             "held vertex from above the terrain; it is 0.4)");
}

TEST(LoadScene, ContactSolveMethodIsChosenByNameWithDidYouMean) {
  const auto dir = testing::FreshDir("contact_solve");
  testing::WriteText(dir / "scene.toml", kPlaneScene);
  EXPECT_EQ(LoadScene((dir / "scene.toml").string()).scene.options.contact_solve,
            ContactSolveMethod::kBlockOnStall);  // the default
  testing::WriteText(
      dir / "scene.toml",
      Replace(kPlaneScene, "max_time_s = 20", "max_time_s = 20\ncontact_solve = \"gauss_seidel\""));
  EXPECT_EQ(LoadScene((dir / "scene.toml").string()).scene.options.contact_solve,
            ContactSolveMethod::kGaussSeidel);
  testing::WriteText(dir / "scene.toml", Replace(kPlaneScene, "max_time_s = 20",
                                                 "max_time_s = 20\ncontact_solve = \"block\""));
  EXPECT_EQ(LoadScene((dir / "scene.toml").string()).scene.options.contact_solve,
            ContactSolveMethod::kBlock);
  EXPECT_HAS(
      ErrorOf(Replace(kPlaneScene, "max_time_s = 20", "max_time_s = 20\ncontact_solve = \"blok\""),
              dir),
      "scene.toml:23: solver.contact_solve: unknown method 'blok' (did you mean 'block'?)");
}

TEST(LoadScene, PredictedLeverIsChosenByNameWithDidYouMean) {
  const auto dir = testing::FreshDir("predicted_lever");
  testing::WriteText(dir / "scene.toml", kPlaneScene);
  EXPECT_EQ(LoadScene((dir / "scene.toml").string()).scene.options.predicted_lever,
            PredictedLever::kMidpoint);  // the default
  testing::WriteText(dir / "scene.toml", Replace(kPlaneScene, "max_time_s = 20",
                                                 "max_time_s = 20\npredicted_lever = \"touch\""));
  EXPECT_EQ(LoadScene((dir / "scene.toml").string()).scene.options.predicted_lever,
            PredictedLever::kTouch);
  EXPECT_HAS(ErrorOf(Replace(kPlaneScene, "max_time_s = 20",
                             "max_time_s = 20\npredicted_lever = \"tuch\""),
                     dir),
             "scene.toml:23: solver.predicted_lever: unknown lever 'tuch' (did you mean 'touch'?)");
}

TEST(LoadScene, ContactHoldIsChosenByNameWithDidYouMean) {
  const auto dir = testing::FreshDir("contact_hold");
  testing::WriteText(dir / "scene.toml", kPlaneScene);
  EXPECT_EQ(LoadScene((dir / "scene.toml").string()).scene.options.contact_hold,
            ContactHold::kMidpoint);  // the default
  testing::WriteText(dir / "scene.toml", Replace(kPlaneScene, "max_time_s = 20",
                                                 "max_time_s = 20\ncontact_hold = \"held\""));
  EXPECT_EQ(LoadScene((dir / "scene.toml").string()).scene.options.contact_hold,
            ContactHold::kHeld);
  EXPECT_HAS(
      ErrorOf(Replace(kPlaneScene, "max_time_s = 20", "max_time_s = 20\ncontact_hold = \"hold\""),
              dir),
      "scene.toml:23: solver.contact_hold: unknown contact hold 'hold' (did you mean "
      "'held'?)");
}

// substep_impacts = "all" splits every step with a new contact: it needs sub-steps and held
// contacts, and a scene without them is told which key is missing.
TEST(LoadScene, SubstepImpactsAllNeedsSubStepsAndHeldContacts) {
  const auto dir = testing::FreshDir("substep_impacts");
  const auto with = [](const std::string& keys) {
    return Replace(kPlaneScene, "max_time_s = 20", "max_time_s = 20\n" + keys);
  };
  testing::WriteText(dir / "scene.toml", kPlaneScene);
  EXPECT_EQ(LoadScene((dir / "scene.toml").string()).scene.options.substep_impacts,
            SubstepImpacts::kFast);  // the default
  testing::WriteText(dir / "scene.toml",
                     with("contact_hold = \"held\"\nsubstep_impacts = \"all\""));
  EXPECT_EQ(LoadScene((dir / "scene.toml").string()).scene.options.substep_impacts,
            SubstepImpacts::kAll);
  EXPECT_HAS(ErrorOf(with("substep_impacts = \"all\""), dir),
             "substep_impacts = \"all\" needs contact_hold = \"held\"");
  EXPECT_HAS(
      ErrorOf(with("contact_hold = \"held\"\nsubstep_impacts = \"all\"\nimpact_substeps = 1"), dir),
      "substep_impacts = \"all\" needs impact_substeps > 1 (it is 1: whole steps)");
  EXPECT_HAS(ErrorOf(with("normal_restitution = 0.4\nsubstep_impacts = \"all\""), dir),
             "substep_impacts = \"all\" needs normal_restitution = 0 (Newton's law keeps whole "
             "steps; it is 0.4)");
  EXPECT_HAS(ErrorOf(with("substep_impacts = \"al\""), dir),
             "solver.substep_impacts: unknown impacts 'al' (did you mean 'all'?)");
}

// [solver] preset sets the accuracy knobs (solver/options.hpp) and keys the scene gives win over
// it; talus simulate --preset (UseSolverPreset) wins over both and names the values it changed.
TEST(LoadScene, SolverPresetSetsTheKnobsTheSceneDoesNotGive) {
  const auto dir = testing::FreshDir("preset");
  const auto load = [&](const std::string& extra) {
    testing::WriteText(dir / "scene.toml", Replace(kPlaneScene, "dt_s = 0.004\nmax_time_s = 20",
                                                   "max_time_s = 20\n" + extra));
    return LoadScene((dir / "scene.toml").string());
  };
  const SolverOptions defaults;
  SceneFile scene = load("");
  EXPECT_EQ(scene.solver_preset, SolverPreset::kDefault);
  EXPECT_EQ(scene.scene.options.tolerance_m_s, defaults.tolerance_m_s);
  scene = load("preset = \"fast\"");
  EXPECT_EQ(scene.solver_preset, SolverPreset::kFast);
  EXPECT_EQ(scene.scene.options.tolerance_m_s, 1e-2);
  EXPECT_EQ(scene.scene.options.dt_s, defaults.dt_s);
  scene = load("preset = \"accurate\"\ntolerance_m_s = 1e-6");
  EXPECT_EQ(scene.scene.options.dt_s, 0.001);
  EXPECT_EQ(scene.scene.options.max_iterations, 1000);
  EXPECT_EQ(scene.scene.options.tolerance_m_s, 1e-6);  // given: kept
  EXPECT_FALSE(scene.solver_preset_from_command_line);
  UseSolverPreset(scene, SolverPreset::kFast);
  EXPECT_EQ(scene.solver_preset, SolverPreset::kFast);
  EXPECT_TRUE(scene.solver_preset_from_command_line);
  EXPECT_EQ(scene.scene.options.dt_s, defaults.dt_s);
  EXPECT_EQ(scene.scene.options.max_iterations, defaults.max_iterations);
  EXPECT_EQ(scene.scene.options.tolerance_m_s, 1e-2);  // the scene's own 1e-6 overridden
  EXPECT_EQ(scene.solver_keys_overridden,
            std::vector<std::string>{"tolerance_m_s = 1e-06 -> 0.01"});
  // The shipped scenes' case: dt_s = 0.002 given, --preset accurate halves it.
  scene = load("dt_s = 0.002");
  UseSolverPreset(scene, SolverPreset::kAccurate);
  EXPECT_EQ(scene.scene.options.dt_s, 0.001);
  EXPECT_EQ(scene.solver_keys_overridden, std::vector<std::string>{"dt_s = 0.002 -> 0.001"});
  EXPECT_HAS(
      ErrorOf(Replace(kPlaneScene, "max_time_s = 20", "max_time_s = 20\npreset = \"fats\""), dir),
      "scene.toml:23: solver.preset: unknown preset 'fats' (did you mean 'fast'?)");
  for (SolverPreset p : {SolverPreset::kFast, SolverPreset::kDefault, SolverPreset::kAccurate}) {
    SolverOptions o;
    ApplyPreset(p, &o);
    std::string why;
    EXPECT_TRUE(o.IsValid(&why)) << ToString(p) << ": " << why;
  }
}

// Every [solver] key of the options table (kSolverOptions) sets its option, and summary.json
// writes the value back under the same key: a valid value other than the default, per row.
TEST(LoadScene, EverySolverOptionOfTheTableIsReadAndWrittenBack) {
  const auto dir = testing::FreshDir("solver_table");
  const SolverOptions defaults;
  int read = 0;
  for (const SolverOptionInfo& f : kSolverOptions) {
    const double fallback = f.member.get(defaults);
    double value = 0;
    std::string text;
    if (f.type == SolverOptionInfo::Type::kChoice) {
      value = std::fmod(fallback + 1, f.choices->size());
      text = std::string("\"") + f.choices->Name(static_cast<int>(value)) + "\"";
    } else {
      const double upper = f.HasPlausibleRange() ? f.plausible_upper : f.valid.upper;
      value = f.type == SolverOptionInfo::Type::kInteger || std::isinf(upper)
                  ? fallback + 1
                  : (fallback + upper) / 2;
      char buffer[64];
      std::snprintf(buffer, sizeof buffer, "%.17g", value);
      text = buffer;
      if (f.type == SolverOptionInfo::Type::kNumber &&
          text.find_first_of(".e") == std::string::npos)
        text += ".0";  // a TOML float
    }
    // The restitution coefficients are one (SolverOptions::IsValid): the pair is given together.
    std::string keys = std::string(f.key) + " = " + text;
    if (std::string(f.key) == "tangential_restitution") keys += "\nnormal_restitution = " + text;
    // Every impact in sub-steps goes with held contacts (io/scene_file.cpp).
    if (std::string(f.key) == "substep_impacts") keys += "\ncontact_hold = \"held\"";
    testing::WriteText(dir / "scene.toml",
                       Replace(kPlaneScene, "dt_s = 0.004\nmax_time_s = 20", keys));
    SceneFile scene;
    try {
      scene = LoadScene((dir / "scene.toml").string());
    } catch (const InputError& e) {
      ADD_FAILURE() << f.key << " = " << text << ": " << e.what();
      continue;
    }
    ++read;
    EXPECT_EQ(f.member.get(scene.scene.options), value) << f.key;
    const auto j = nlohmann::json::parse(SummaryJson(scene, ensemble::EnsembleReport{}, "0", {}));
    const nlohmann::json& written = j["solver"][f.key];
    if (f.choices) {
      EXPECT_EQ(written, f.choices->Name(static_cast<int>(value))) << f.key;
    } else if (f.type == SolverOptionInfo::Type::kInteger) {
      EXPECT_TRUE(written.is_number_integer()) << f.key;
      EXPECT_EQ(written.get<double>(), value) << f.key;
    } else {
      EXPECT_EQ(written.get<double>(), value) << f.key;
    }
  }
  EXPECT_EQ(read, static_cast<int>(kSolverOptions.size()));
}

// penetration_tolerance: a fraction of the rock's thickness in (0, 0.5], read from [solver] and
// refused out of its bounds with a message naming the key.
TEST(LoadScene, PenetrationToleranceIsASolverKeyWithItsBounds) {
  const auto dir = testing::FreshDir("penetration_tolerance");
  const auto with = [](const std::string& keys) {
    return Replace(kPlaneScene, "max_time_s = 20", "max_time_s = 20\n" + keys);
  };
  testing::WriteText(dir / "scene.toml", kPlaneScene);
  EXPECT_EQ(LoadScene((dir / "scene.toml").string()).scene.options.penetration_tolerance, 0.01);
  testing::WriteText(dir / "scene.toml", with("penetration_tolerance = 0.05"));
  EXPECT_EQ(LoadScene((dir / "scene.toml").string()).scene.options.penetration_tolerance, 0.05);
  EXPECT_HAS(ErrorOf(with("penetration_tolerance = 0.8"), dir),
             "scene.toml:23: solver.penetration_tolerance: penetration_tolerance = 0.8 violates "
             "0 < penetration_tolerance <= 0.5");
  EXPECT_HAS(ErrorOf(with("penetration_tolerance = 0"), dir),
             "solver.penetration_tolerance: penetration_tolerance = 0 violates");
  EXPECT_HAS(ErrorOf(with("penetration_tolerance = -1"), dir),
             "solver.penetration_tolerance: penetration_tolerance = -1 violates");
}

// docs/scenes.md's rows of [output] rasters and raster_format name the values of the code's tables
// (ensemble::kRasterKindNames, kRasterFormatNames), in their order.
TEST(LoadScene, DocsNameTheRastersAndFormatsOfTheTables) {
  std::ifstream in(std::string(TALUS_SOURCE_DIR) + "/docs/scenes.md");
  ASSERT_TRUE(in) << "docs/scenes.md";
  std::string rasters, formats;
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("| `rasters` |", 0) == 0) rasters = line;
    if (line.rfind("| `raster_format` |", 0) == 0) formats = line;
  }
  std::string names, quoted;
  for (int k = 0; k < ensemble::kRasterKindNames.size(); ++k)
    names += (k ? ", `" : "`") + std::string(ensemble::kRasterKindNames.Name(k)) + "`";
  EXPECT_HAS(rasters, "| any of " + names + ";");
  for (int k = 0; k < kRasterFormatNames.size(); ++k)
    EXPECT_HAS(formats, "`\"" + std::string(kRasterFormatNames.Name(k)) + "\"`");
}

// [output] percentiles: integers 1 .. 99, sorted and without repeats; the default is the p95
// rasters of earlier versions. raster_format: "gtiff" (default) or "cog".
TEST(LoadScene, PercentilesAndRasterFormatOfTheOutput) {
  const auto dir = testing::FreshDir("percentiles");
  testing::WriteText(dir / "scene.toml", kPlaneScene);
  const SceneFile plain = LoadScene((dir / "scene.toml").string());
  EXPECT_EQ(plain.output.percentiles, std::vector<int>{95});
  EXPECT_EQ(plain.output.raster_format, RasterFormat::kGeoTiff);
  const GridGeometry& grid = plain.scene.terrain.heights().grid;
  EXPECT_EQ(plain.output.Request(grid).percentiles, std::vector<int>{95});
  std::string why;
  EXPECT_TRUE(plain.output.Request(grid).IsValid(&why)) << why;

  const std::string rasters = "rasters = [\"speed\", \"reach_probability\"]";
  testing::WriteText(dir / "scene.toml",
                     Replace(kPlaneScene, rasters,
                             rasters + "\npercentiles = [99, 1, 50, 99]\nraster_format = \"cog\""));
  const SceneFile chosen = LoadScene((dir / "scene.toml").string());
  EXPECT_EQ(chosen.output.percentiles, (std::vector<int>{1, 50, 99}));
  EXPECT_EQ(chosen.output.Request(grid).percentiles, (std::vector<int>{1, 50, 99}));
  EXPECT_EQ(chosen.output.raster_format, RasterFormat::kCog);
  testing::WriteText(dir / "scene.toml",
                     Replace(kPlaneScene, rasters, rasters + "\npercentiles = []"));
  EXPECT_TRUE(LoadScene((dir / "scene.toml").string()).output.percentiles.empty());

  const auto error = [&](const std::string& line) {
    return ErrorOf(Replace(kPlaneScene, rasters, rasters + "\n" + line), dir);
  };
  EXPECT_HAS(error("percentiles = [95, 100]"),
             "scene.toml:28: output.percentiles: 100 is out of range (1 .. 99)");
  EXPECT_HAS(error("percentiles = [0]"), "output.percentiles: 0 is out of range (1 .. 99)");
  EXPECT_HAS(error("percentiles = [-5]"), "output.percentiles: -5 is out of range (1 .. 99)");
  EXPECT_HAS(error("percentiles = [95.5]"),
             "output.percentiles: expected a list of integer percents in 1 .. 99");
  EXPECT_HAS(error("percentiles = [\"p95\"]"),
             "output.percentiles: expected a list of integer percents in 1 .. 99");
  EXPECT_HAS(error("percentiles = 95"),
             "output.percentiles: expected a list of integer percents in 1 .. 99");
  EXPECT_HAS(error("raster_format = \"cogg\""),
             "scene.toml:28: output.raster_format: unknown format 'cogg' (did you mean 'cog'?); "
             "known: gtiff, cog");
  EXPECT_HAS(error("raster_format = true"), "output.raster_format: expected a string");
  EXPECT_HAS(error("percentile = [95]"),
             "output.percentile: unknown key (did you mean 'percentiles'?)");
}

TEST(LoadScene, ReleaseOutsideTheDemIsAnError) {
  const auto dir = testing::FreshDir("outside");
  const std::string e = ErrorOf(Replace(kPlaneScene, "[6, 2]", "[6, 200]"), dir);
  EXPECT_HAS(e,
             "scene.toml:10: release.points[1]: (6, 200) is outside the DEM or on nodata (the DEM "
             "covers x 0 .. "
             "60, y -15 .. 15)");
  EXPECT_HAS(ErrorOf(Replace(kPlaneScene, "[10, 2], [8, 2]", "[10, 2], [-8, 2]"), dir),
             "release.polygons[0]");
}

// A release polygon of (nearly) no area would start every rock at its first vertex; one of
// coordinates whose area overflows is out of range. Both name the polygon and its line.
TEST(LoadScene, SliverAndOutOfRangePolygonsAreErrors) {
  const auto dir = testing::FreshDir("sliver");
  const std::string polygon = "polygons = [[[8, -2], [10, -2], [10, 2], [8, 2]]]";
  EXPECT_HAS(ErrorOf(Replace(kPlaneScene, polygon,
                             "polygons = [[[8, -2], [10, -2], [10, 2], [8, 2]],\n"
                             "            [[8, -2], [10, 0], [9.999999, 0.000001]]]"),
                     dir),
             "scene.toml:13: release.polygons[1]: a sliver: its area (");
  const std::string far = ErrorOf(
      Replace(kPlaneScene, polygon, "polygons = [[[8, -2], [1e300, -2], [8, 1e300]]]"), dir);
  EXPECT_HAS(far, "scene.toml:12: release.polygons[0]: coordinates out of range");
  EXPECT_EQ(far.find("collinear"), std::string::npos) << far;
}

TEST(LoadScene, MissingPiecesAndFiles) {
  const auto dir = testing::FreshDir("missing");
  EXPECT_HAS(ErrorOf("[terrain]\nplane = {}\n[rock]\nshape = { box = [1, 1, 1] }\n", dir),
             "release: missing table");
  EXPECT_HAS(ErrorOf(Replace(kPlaneScene, "plane = {", "dem = \"nowhere.tif\"\nplane = {"), dir),
             "give exactly one of 'dem' and 'plane'");
  const std::string e = ErrorOf(Replace(kPlaneScene,
                                        "plane = { slope_deg = 35, slope_length_m = 40, runout_m = "
                                        "20, width_m = 30, cell_m = 1 }",
                                        "dem = \"nowhere.tif\""),
                                dir);
  EXPECT_HAS(e, "scene.toml:2: terrain.dem: file not found: ");
  EXPECT_HAS(e, "nowhere.tif");
  EXPECT_HAS(ErrorOf(Replace(kPlaneScene, "{ box = [0.5, 0.4, 0.3] }", "\"rock.ply\""), dir),
             "rock.shape: file not found");
  EXPECT_HAS(ErrorOf(std::string(kPlaneScene) + "[ground.scree]\ncode = 11\n", dir),
             "ground.scree.mu_min: missing");
}

const std::array<double, 6> kGeo = {1000.0, 10.0, 0.0,
                                    2050.0, 0.0,  -10.0};  // 10 m cells, north edge y = 2050

// A DEM sloping down to the east, with its ground map on a coarser grid, in a subfolder.
void WriteDemCase(const std::filesystem::path& dir) {
  std::filesystem::create_directories(dir / "data");
  std::vector<std::vector<double>> dem(5, std::vector<double>(6));
  for (int r = 0; r < 5; ++r)
    for (int c = 0; c < 6; ++c) dem[r][c] = 100.0 - 5.0 * c;
  dem[0][5] = -9999;
  testing::WriteGdalRaster(dir / "data" / "dem.tif", dem, kGeo, 31287, -9999.0);
  // Ground: 3 x 3 cells of 20 m; codes 6 (hard), 11 (user scree), 255 (nodata -> default).
  testing::WriteGdalRaster(dir / "data" / "ground.tif", {{6, 6, 11}, {6, 11, 11}, {255, 11, 11}},
                           {1000.0, 20.0, 0.0, 2050.0, 0.0, -20.0}, 31287, 255.0);
}

const char* kDemScene = R"([terrain]
dem = "data/dem.tif"
ground = "data/ground.tif"
default_ground = "medium"

[ground.my_scree]
code = 11
mu_min = 0.5
mu_max = 2.0
beta = 180
kappa = 3.0
nu = 0.4

[ground.medium]
mu_min = 0.36

[rock]
shape = { sphere = 0.3 }

[release]
points = [[1015, 2015]]
)";

TEST(LoadScene, GdalDemGroundRasterAndUserCategories) {
  const auto dir = testing::FreshDir("dem");
  WriteDemCase(dir);
  testing::WriteText(dir / "scene.toml", kDemScene);
  const SceneFile s = LoadScene((dir / "scene.toml").string());
  const Terrain& t = s.scene.terrain;
  EXPECT_EQ(t.heights().grid.nx, 6);
  EXPECT_DOUBLE_EQ(t.heights().grid.x0_m, 1005);
  EXPECT_DOUBLE_EQ(t.heights().grid.y0_m, 2005);
  TerrainSample sample;
  ASSERT_TRUE(t.Sample(1015, 2015, &sample));
  EXPECT_NEAR(sample.height_m, 95, 1e-9);
  EXPECT_FALSE(t.Sample(1055, 2045, &sample));  // the nodata corner
  const GroundTable& g = s.scene.ground;
  EXPECT_EQ(t.GroundAt(1005, 2045), g.IndexOfName("hard"));      // north-west ground cell, code 6
  EXPECT_EQ(t.GroundAt(1055, 2045), g.IndexOfName("my_scree"));  // north-east, code 11
  EXPECT_EQ(t.GroundAt(1005, 2005), g.IndexOfName("medium"));    // south-west nodata: the default
  EXPECT_DOUBLE_EQ(g.params(g.IndexOfName("medium")).mu_min,
                   0.36);  // override keeps the other values
  EXPECT_DOUBLE_EQ(g.params(g.IndexOfName("medium")).beta_1_s, 150);
  EXPECT_NE(s.crs_wkt.find("Austria Lambert"), std::string::npos);
  EXPECT_EQ(s.inputs.size(), 3u);
}

TEST(LoadScene, GdalDemErrors) {
  const auto dir = testing::FreshDir("dem_errors");
  WriteDemCase(dir);
  EXPECT_HAS(ErrorOf(Replace(kDemScene, "[[1015, 2015]]", "[[1055, 2045]]"), dir),
             "outside the DEM or on nodata");
  EXPECT_HAS(ErrorOf(Replace(kDemScene, "code = 11", "code = 12"), dir),
             "terrain.ground: " + (dir / "data" / "ground.tif").string() + " has the value 11");
  EXPECT_HAS(ErrorOf(Replace(kDemScene, "code = 11", "code = 6"), dir),
             "ground.my_scree.code: 6 is already the code of 'hard'");
  testing::WriteGdalRaster(dir / "data" / "ground_wgs84.tif", {{6}},
                           {11.0, 0.1, 0.0, 47.0, 0.0, -0.1}, 4326, 255.0);
  // A ground raster in degrees under a projected DEM is reprojected: this one is of another place
  // (Austria, where the DEM's coordinates are near the origin of the Lambert projection).
  EXPECT_HAS(ErrorOf(Replace(kDemScene, "\"data/ground.tif\"", "\"data/ground_wgs84.tif\""), dir),
             "scene.toml:3: terrain.ground: " + (dir / "data" / "ground_wgs84.tif").string() +
                 " covers x");
  EXPECT_HAS(ErrorOf(Replace(kDemScene, "\"data/ground.tif\"", "\"data/ground_wgs84.tif\""), dir),
             "which does not overlap the DEM");
  EXPECT_HAS(ErrorOf(Replace(kDemScene, "\"data/ground.tif\"", "\"data/grund.tif\""), dir),
             "scene.toml:3: terrain.ground: file not found");
}

// Rocks start anywhere along a line or inside a polygon: nodata there is an error before any rock
// runs, even when every vertex is on valid terrain (it used to start such rocks at z = height_m
// and count them as having left the domain).
TEST(LoadScene, ReleaseOverNodataBetweenVerticesIsAnError) {
  const auto dir = testing::FreshDir("nodata_inside");
  std::filesystem::create_directories(dir / "data");
  std::vector<std::vector<double>> dem(7, std::vector<double>(7, 500.0));
  dem[3][3] =
      -9999;  // the node at (1035, 2015): cells x 1025 .. 1045, y 2005 .. 2025 have no height
  testing::WriteGdalRaster(dir / "data" / "dem.tif", dem, kGeo, 31287, -9999.0);
  const std::string scene =
      "[terrain]\ndem = \"data/dem.tif\"\n[rock]\nshape = { sphere = 0.3 }\n[release]\n";
  const std::string line = ErrorOf(scene + "lines = [[[1015, 2015], [1055, 2015]]]\n", dir);
  EXPECT_HAS(line, "release.lines[0]: (");
  EXPECT_HAS(line, "is outside the DEM or on nodata");
  const std::string polygon = ErrorOf(
      scene + "polygons = [[[1015, 1995], [1055, 1995], [1055, 2035], [1015, 2035]]]\n", dir);
  EXPECT_HAS(polygon,
             "release.polygons[0]: (1030, 2010) is outside the DEM or on nodata");  // a cell centre
  EXPECT_EQ(ErrorOf(scene + "lines = [[[1015, 2035], [1055, 2035]]]\n", dir), "");
}

TEST(LoadScene, OutOfRangeIntegersAreErrors) {
  const auto dir = testing::FreshDir("integers");
  // 2^32 + 1 used to wrap to max_iterations = 1.
  EXPECT_HAS(ErrorOf(Replace(kPlaneScene, "max_time_s = 20",
                             "max_time_s = 20\nmax_iterations = 4294967297"),
                     dir),
             "solver.max_iterations: 4294967297 is out of range");
  EXPECT_HAS(ErrorOf(Replace(kPlaneScene, "rocks = 7", "rocks = 9223372036854775807"), dir),
             "is more than");
  // A ground value far outside any code (converting it to int was undefined behaviour).
  WriteDemCase(dir);
  testing::WriteGdalRaster(dir / "data" / "ground_huge.tif",
                           {{6, 6, 11}, {6, 11, 11}, {255, 11, 1e20}},
                           {1000.0, 20.0, 0.0, 2050.0, 0.0, -20.0}, 31287, 255.0);
  EXPECT_HAS(ErrorOf(Replace(kDemScene, "\"data/ground.tif\"", "\"data/ground_huge.tif\""), dir),
             "has the value 1e+20");
}

// The built-in rock: { rock = [a, b, c] } with its knobs; given dimensions and a mass, the
// dimensions stay and the density follows (mass / volume, to rounding: 1e-12 relative).
TEST(LoadScene, BuiltInRockWithItsKnobs) {
  const auto dir = testing::FreshDir("rock");
  const std::string shape =
      "{ rock = [0.46, 0.30, 0.20], points = 24, roughness = 0.3, "
      "shape_seed = 9 }";
  const std::string scene = Replace(Replace(kPlaneScene, "{ box = [0.5, 0.4, 0.3] }", shape),
                                    "density_kg_m3 = 2600", "mass_kg = 40");
  testing::WriteText(dir / "scene.toml", scene);
  const SceneFile s = LoadScene((dir / "scene.toml").string());
  EXPECT_EQ(s.rock.builtin, "rock");
  EXPECT_EQ(s.rock.points, 24);
  EXPECT_DOUBLE_EQ(s.rock.roughness, 0.3);
  EXPECT_EQ(s.rock.shape_seed, 9u);
  EXPECT_EQ(s.rock_description, "rock 0.46 x 0.3 x 0.2 m, 24 points, roughness 0.3, seed 9");
  EXPECT_LE(s.scene.rock.vertices_m.size(), 24u);
  EXPECT_NEAR(s.scene.rock.mass_kg, 40, 40e-12);

  EXPECT_HAS(ErrorOf(Replace(scene, "points = 24", "points = 3"), dir),
             "scene.toml:6: rock.shape.points: 3 must be in 4 .. 1000000");
  EXPECT_HAS(ErrorOf(Replace(scene, "roughness = 0.3", "roughness = 0.7"), dir),
             "scene.toml:6: rock.shape.roughness: 0.7 must be in 0 .. 0.5");
  EXPECT_HAS(ErrorOf(Replace(scene, "shape_seed = 9", "shape_seed = -9"), dir),
             "rock.shape.shape_seed: -9 must be >= 0");
  EXPECT_HAS(ErrorOf(Replace(scene, "shape_seed = 9", "shape_seed = 1.5"), dir),
             "rock.shape.shape_seed: expected an integer");
  EXPECT_HAS(ErrorOf(Replace(scene, "rock = [0.46, 0.30, 0.20]", "box = [0.46, 0.30, 0.20]"), dir),
             "rock.shape.points: only a rock shape takes points");
  EXPECT_HAS(ErrorOf(Replace(scene, "mass_kg = 40", "mass_kg = 40\ndensity_kg_m3 = 2600"), dir),
             "rock.mass_kg: the dimensions of the shape and mass_kg fix the density");
  EXPECT_HAS(ErrorOf(Replace(scene, "mass_kg = 40", "volume_m3 = 0.1"), dir),
             "scene.toml:7: rock.volume_m3: the dimensions of the shape fix its volume");
}

// Point cloud files go through the pointclouds module: the hull of the points is the rock.
TEST(LoadScene, PointCloudFileIsTheRocksHull) {
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

// A ground raster in UTM zone 32N (EPSG:32632) under a DEM in the Swiss LV95 (EPSG:2056), the two
// grids rotated by about 1.3 degrees: reprojected by nearest neighbour, the category at a point is
// the file's category at that point's UTM coordinates. The map is a checkerboard of 100 m blocks
// of codes 6 and 7 on 5 m cells; points within 15 m of a block edge (three cells) are not
// compared.
TEST(LoadScene, GroundRasterInAnotherCrsIsReprojected) {
  const auto dir = testing::FreshDir("ground_utm");
  std::filesystem::create_directories(dir / "data");
  const double e0 = 2700000, n0 = 1250000;  // LV95, near Zurich
  std::vector<std::vector<double>> dem(100, std::vector<double>(100));
  for (int r = 0; r < 100; ++r)
    for (int c = 0; c < 100; ++c) dem[r][c] = 500 - 0.2 * c;
  testing::WriteGdalRaster(dir / "data" / "dem.tif", dem, {e0, 10.0, 0.0, n0 + 1000, 0.0, -10.0},
                           2056, std::nullopt);
  OGRSpatialReference lv95, utm;
  lv95.importFromEPSG(2056);
  utm.importFromEPSG(32632);
  lv95.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  utm.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  std::unique_ptr<OGRCoordinateTransformation> to_utm(
      OGRCreateCoordinateTransformation(&lv95, &utm));
  double x[2] = {e0 - 200, e0 + 1200}, y[2] = {n0 - 200, n0 + 1200};
  ASSERT_TRUE(to_utm->Transform(2, x, y));  // corners, with a margin
  const double ux0 = std::floor(std::min(x[0], x[1]) / 100) * 100 - 100;
  const double uy1 = std::ceil(std::max(y[0], y[1]) / 100) * 100 + 100;
  const int nx = 360, ny = 360;  // 1800 m of 5 m cells
  const auto code_at = [](double ux, double uy) {
    return (static_cast<long>(std::floor(ux / 100)) + static_cast<long>(std::floor(uy / 100))) % 2
               ? 7
               : 6;
  };
  std::vector<std::vector<double>> codes(ny, std::vector<double>(nx));
  for (int r = 0; r < ny; ++r)
    for (int c = 0; c < nx; ++c) codes[r][c] = code_at(ux0 + 5 * c + 2.5, uy1 - 5 * r - 2.5);
  testing::WriteGdalRaster(dir / "data" / "ground.tif", codes, {ux0, 5.0, 0.0, uy1, 0.0, -5.0},
                           32632, std::nullopt);
  testing::WriteText(dir / "scene.toml",
                     "[terrain]\ndem = \"data/dem.tif\"\nground = \"data/ground.tif\"\n"
                     "[rock]\nshape = { sphere = 0.3 }\n[release]\npoints = [[" +
                         std::to_string(e0 + 500) + ", " + std::to_string(n0 + 500) + "]]\n");
  const SceneFile s = LoadScene((dir / "scene.toml").string());
  EXPECT_HAS(s.terrain_description, "ground map reprojected from EPSG:32632");
  std::mt19937_64 rng(3);
  talus::testing::UniformReal<double> u(5, 995);
  int compared = 0;
  for (int k = 0; k < 400; ++k) {
    double px = e0 + u(rng), py = n0 + u(rng);
    const int index = s.scene.terrain.GroundAt(px, py);
    ASSERT_TRUE(to_utm->Transform(1, &px, &py));
    const double edge = std::min({std::fmod(px, 100.0), 100 - std::fmod(px, 100.0),
                                  std::fmod(py, 100.0), 100 - std::fmod(py, 100.0)});
    if (edge < 15) continue;
    ++compared;
    EXPECT_EQ(s.scene.ground.category(index).code, code_at(px, py)) << px << ", " << py;
  }
  EXPECT_GT(compared, 100);
}

// Ground polygons in GeoJSON (with the DEM's CRS) over the DEM case: rasterised onto the DEM's
// nodes (cell centres inside a polygon), later polygons over earlier ones, polygons over the
// ground raster; categories by name or code.
void WritePolygons(const std::filesystem::path& path, const std::string& features) {
  testing::WriteText(path, R"({"type": "FeatureCollection", "crs": {"type": "name", "properties": )"
                           R"({"name": "urn:ogc:def:crs:EPSG::31287"}}, "features": [)" +
                               features + "]}");
}

std::string Feature(const std::string& properties, const std::string& geometry) {
  std::ostringstream out;
  out << R"({"type": "Feature", "properties": {)" << properties << R"(}, "geometry": )" << geometry
      << "}";
  return out.str();
}

std::string Square(double x0, double y0, double x1, double y1) {
  std::ostringstream out;
  out << R"({"type": "Polygon", "coordinates": [[)";
  const double xs[5] = {x0, x1, x1, x0, x0}, ys[5] = {y0, y0, y1, y1, y0};
  for (int k = 0; k < 5; ++k) out << (k ? ", [" : "[") << xs[k] << ", " << ys[k] << "]";
  out << "]]}";
  return out.str();
}

TEST(LoadScene, GroundPolygonsAreRasterisedOntoTheDem) {
  const auto dir = testing::FreshDir("ground_polygons");
  WriteDemCase(dir);
  // Scree over x 1020 .. 1050, y 2010 .. 2040 (nodes x 1025, 1035, 1045 and y 2015, 2025, 2035),
  // then snow by code (8) over x 1040 .. 1060, y 2030 .. 2050, drawn over the scree.
  WritePolygons(dir / "data" / "ground.geojson",
                Feature(R"("category": "my_scree", "code": 11)", Square(1020, 2010, 1050, 2040)) +
                    ", " +
                    Feature(R"("category": "8", "code": 8)", Square(1040, 2030, 1060, 2050)));
  const std::string no_raster =
      Replace(kDemScene, "ground = \"data/ground.tif\"",
              "ground_polygons = { file = \"data/ground.geojson\", field = \"category\" }");
  testing::WriteText(dir / "scene.toml", no_raster);
  const SceneFile s = LoadScene((dir / "scene.toml").string());
  const Terrain& t = s.scene.terrain;
  const GroundTable& g = s.scene.ground;
  const int scree = g.IndexOfName("my_scree"), snow = g.IndexOfName("snow");
  int inside = 0;
  for (double x = 1005; x <= 1055; x += 10)
    for (double y = 2005; y <= 2045; y += 10) {
      const bool in_snow = x > 1040 && y > 2030,
                 in_scree = x > 1020 && x < 1050 && y > 2010 && y < 2040;
      const int expected = in_snow ? snow : in_scree ? scree : g.IndexOfName("medium");
      EXPECT_EQ(t.GroundAt(x, y), expected) << x << ", " << y;
      inside += t.GroundAt(x, y) == scree;
    }
  EXPECT_EQ(inside, 9 - 1);  // 9 nodes in the scree square, one of them under the snow
  // A contact inside gets the scree's parameters (contacts look their ground up by GroundAt).
  EXPECT_DOUBLE_EQ(g.params(t.GroundAt(1026, 2016)).mu_min, 0.5);
  EXPECT_EQ(s.inputs.size(), 3u);

  // By code, and over the ground raster: the raster where no polygon covers a node.
  testing::WriteText(dir / "scene.toml",
                     Replace(kDemScene, "default_ground",
                             "ground_polygons = { file = \"data/ground.geojson\", field = \"code\" "
                             "}\ndefault_ground"));
  const SceneFile both = LoadScene((dir / "scene.toml").string());
  EXPECT_EQ(both.scene.terrain.GroundAt(1005, 2045), g.IndexOfName("hard"));    // raster code 6
  EXPECT_EQ(both.scene.terrain.GroundAt(1005, 2005), g.IndexOfName("medium"));  // raster nodata
  EXPECT_EQ(both.scene.terrain.GroundAt(1025, 2015), scree);  // a polygon over raster code 6
  EXPECT_EQ(both.scene.terrain.GroundAt(1055, 2045), snow);   // over raster code 11

  // Errors: a missing field, an unknown category, a line, a file off the DEM, keys.
  const std::string path = (dir / "data" / "ground.geojson").string();
  EXPECT_HAS(ErrorOf(Replace(no_raster, "\"category\" }", "\"kind\" }"), dir),
             "scene.toml:3: terrain.ground_polygons (" + path +
                 ", feature 0): no field 'kind' (the fields are: category, code)");
  WritePolygons(dir / "data" / "ground.geojson",
                Feature(R"("category": "scre")", Square(1020, 2010, 1050, 2040)));
  EXPECT_HAS(ErrorOf(no_raster, dir),
             "feature 0): field 'category' is 'scre', which is neither the name nor the code of a "
             "ground category");
  WritePolygons(
      dir / "data" / "ground.geojson",
      Feature(R"("category": "hard")", Square(1020, 2010, 1050, 2040)) + ", " +
          Feature(R"("category": "hard")",
                  R"({"type": "LineString", "coordinates": [[1020, 2010], [1050, 2040]]})"));
  EXPECT_HAS(ErrorOf(no_raster, dir),
             "feature 1): a ground polygon must be a polygon, not a LINESTRING");
  WritePolygons(dir / "data" / "ground.geojson",
                Feature(R"("category": "hard")", Square(5000, 5000, 5100, 5100)));
  EXPECT_HAS(ErrorOf(no_raster, dir), "covers no cell centre of the DEM");
  EXPECT_HAS(ErrorOf(Replace(no_raster, ", field = \"category\"", ""), dir),
             "terrain.ground_polygons.field: missing");
  EXPECT_HAS(ErrorOf(Replace(no_raster, "field =", "feld ="), dir),
             "terrain.ground_polygons.feld: unknown key (did you mean 'field'?)");
  EXPECT_HAS(ErrorOf(Replace(no_raster, "data/ground.geojson", "data/nope.geojson"), dir),
             "file not found");
}

// A scan of an ellipsoid with semi-axes 1.4 x 1.0 x 0.8 m (6000 points on its surface) and
// `outliers` stray returns 3 .. 10 m from its centre, as an .xyz file.
void WriteScan(const std::filesystem::path& path, int outliers) {
  std::mt19937_64 rng(51);
  talus::testing::Normal g;
  talus::testing::UniformReal<double> r(3, 10);
  std::ofstream out(path);
  out.precision(17);
  for (int i = 0; i < 6000; ++i) {
    const Eigen::Vector3d d = Eigen::Vector3d(g(rng), g(rng), g(rng)).normalized();
    out << 1.4 * d.x() << " " << 1.0 * d.y() << " " << 0.8 * d.z() << "\n";
  }
  for (int i = 0; i < outliers; ++i) {
    const Eigen::Vector3d d = Eigen::Vector3d(g(rng), g(rng), g(rng)).normalized() * r(rng);
    out << d.x() << " " << d.y() << " " << d.z() << "\n";
  }
}

// A scan with 1 % stray returns: the default scene gives the clean rock (4/3 pi abc = 4.69 m^3,
// the hull of 6000 surface points within 1 % of it), with cleaning off the scene warns (and
// summary.json lists the warning); a clean scan gives no warning and the same hull either way.
TEST(LoadScene, PointCloudsAreCleanedByDefaultAndDominatedHullsWarn) {
  const auto dir = testing::FreshDir("clean");
  WriteScan(dir / "clean.xyz", 0);
  WriteScan(dir / "dirty.xyz", 60);
  const std::string scene =
      "[terrain]\nplane = {}\n[rock]\nshape = \"dirty.xyz\"\n[release]\npoints = [[10, 0]]\n";
  const double ellipsoid_m3 = 4.0 / 3.0 * std::acos(-1.0) * 1.4 * 1.0 * 0.8;
  testing::WriteText(dir / "scene.toml", scene);
  const SceneFile cleaned = LoadScene((dir / "scene.toml").string());
  EXPECT_NEAR(cleaned.scene.rock.volume_m3, ellipsoid_m3, 0.01 * ellipsoid_m3);
  EXPECT_TRUE(cleaned.warnings.empty());

  testing::WriteText(dir / "scene.toml", Replace(scene, "[release]", "clean = false\n[release]"));
  const SceneFile kept = LoadScene((dir / "scene.toml").string());
  EXPECT_GT(kept.scene.rock.volume_m3, 10 * ellipsoid_m3);
  ASSERT_EQ(kept.warnings.size(), 1u);
  EXPECT_HAS(kept.warnings[0], "scene.toml:4: rock.shape: " + (dir / "dirty.xyz").string() +
                                   ": a few points dominate the rock's hull");
  ensemble::EnsembleReport report;
  const auto j = nlohmann::json::parse(SummaryJson(kept, report, "0", {}));
  EXPECT_EQ(j["warnings"][0], kept.warnings[0]);

  // Outlier removal off by its own key: the same.
  testing::WriteText(dir / "scene.toml",
                     Replace(scene, "[release]", "clean = { outlier_neighbours = 0 }\n[release]"));
  EXPECT_EQ(LoadScene((dir / "scene.toml").string()).warnings.size(), 1u);

  // The clean scan: no warning, and cleaning leaves its hull as it is.
  const std::string clean_scene = Replace(scene, "dirty.xyz", "clean.xyz");
  testing::WriteText(dir / "scene.toml", clean_scene);
  const SceneFile a = LoadScene((dir / "scene.toml").string());
  testing::WriteText(dir / "scene.toml",
                     Replace(clean_scene, "[release]", "clean = false\n[release]"));
  const SceneFile b = LoadScene((dir / "scene.toml").string());
  EXPECT_TRUE(a.warnings.empty());
  EXPECT_TRUE(b.warnings.empty());
  EXPECT_EQ(a.scene.rock.volume_m3, b.scene.rock.volume_m3);
  EXPECT_EQ(a.scene.rock.vertices_m, b.scene.rock.vertices_m);
  EXPECT_NEAR(a.scene.rock.volume_m3, ellipsoid_m3, 0.01 * ellipsoid_m3);
}

TEST(LoadScene, CleanOptionsAreCheckedByName) {
  const auto dir = testing::FreshDir("clean_errors");
  WriteScan(dir / "scan.xyz", 0);
  const std::string scene =
      "[terrain]\nplane = {}\n[rock]\nshape = \"scan.xyz\"\nclean = CLEAN\n"
      "[release]\npoints = [[10, 0]]\n";
  EXPECT_HAS(ErrorOf(Replace(scene, "CLEAN", "{ outlier_neighbors = 8 }"), dir),
             "scene.toml:5: rock.clean.outlier_neighbors: unknown key (did you mean "
             "'outlier_neighbours'?)");
  EXPECT_HAS(ErrorOf(Replace(scene, "CLEAN", "{ outlier_std_ratio = -1 }"), dir),
             "scene.toml:5: rock.clean.outlier_std_ratio: outlier_std_ratio = -1 violates");
  EXPECT_HAS(ErrorOf(Replace(scene, "CLEAN", "{ outlier_passes = 0 }"), dir),
             "rock.clean.outlier_passes: outlier_passes = 0 violates 1 <= outlier_passes <= 100");
  EXPECT_HAS(ErrorOf(Replace(scene, "CLEAN", "{ voxel_m = \"fine\" }"), dir),
             "rock.clean.voxel_m: expected a number");
  EXPECT_HAS(ErrorOf(Replace(scene, "CLEAN", "\"yes\""), dir),
             "rock.clean: expected false or an inline table");
  EXPECT_HAS(ErrorOf("[terrain]\nplane = {}\n[rock]\nshape = { box = [1, 1, 1] }\nclean = false\n"
                     "[release]\npoints = [[10, 0]]\n",
                     dir),
             "rock.clean: only a point cloud file is cleaned");
  // Every field by its name.
  EXPECT_EQ(ErrorOf(Replace(scene, "CLEAN",
                            "{ drop_non_finite = true, drop_duplicates = true, "
                            "outlier_neighbours = 8, outlier_std_ratio = 5, "
                            "outlier_spacing_ratio = 4, outlier_passes = 3, voxel_m = 0.01 }"),
                    dir),
            "");
}

}  // namespace
}  // namespace talus::io

namespace talus::io {
namespace {

const char* kRunScene = R"([terrain]
plane = { slope_deg = 35, slope_length_m = 40, runout_m = 20, width_m = 30, cell_m = 1 }

[blocks]
file = "blocks.csv"
shape = "box"

[blocks.slab]
size_m = [1.0, 0.5, 0.2]
mass_kg = 250

[release]
runs = "runs.csv"
rocks = 3
)";

const char* kBlocksCsv =
    "block_id,name,mass_kg,size_x_m,size_y_m,size_z_m\n"
    "1,\"St. Leonard, the first\",69,0.37,0.32,0.37\n"
    "4,Plate,40,0.46,0.30,0.20\n";

TEST(LoadScene, RunTableWithBlocksLoadsAsGiven) {
  const auto dir = testing::FreshDir("runs");
  testing::WriteText(dir / "blocks.csv", kBlocksCsv);
  testing::WriteText(dir / "runs.csv",
                     "trajectory_id,x_m,y_m,z_m,vx_mps,vy_mps,vz_mps,block_id,extra\n"
                     "v1,5,0,30,1,2,3,4,ignored\n"
                     "v2,6,1,,0,0,0,slab,\n"
                     "v3,7,-1,,,,,1,\n");
  testing::WriteText(dir / "scene.toml", kRunScene);
  const SceneFile s = LoadScene((dir / "scene.toml").string());
  ASSERT_EQ(s.release.runs.size(), 3u);
  ASSERT_EQ(s.release.blocks.size(), 3u);
  EXPECT_EQ(s.release.total_rocks(), 9);
  const ensemble::ReleaseRun& v1 = s.release.runs[0];
  EXPECT_EQ(v1.id, "v1");
  EXPECT_EQ(v1.xy_m, Eigen::Vector2d(5, 0));
  ASSERT_TRUE(v1.z_m.has_value());
  EXPECT_EQ(*v1.z_m, 30);
  EXPECT_EQ(v1.velocity_m_s, Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(s.release.blocks[static_cast<std::size_t>(v1.block)].id, "4");
  EXPECT_FALSE(s.release.runs[1].z_m.has_value());  // height_m above ground instead
  EXPECT_EQ(s.release.blocks[static_cast<std::size_t>(s.release.runs[1].block)].id, "slab");
  // A block of given size and mass keeps its size; the density follows (0.46 x 0.30 x 0.20 m box).
  const RockShape& plate = *s.release.blocks[1].shape;
  EXPECT_NEAR(plate.mass_kg, 40, 1e-9);
  EXPECT_NEAR(plate.volume_m3, 0.46 * 0.30 * 0.20, 1e-12);
  EXPECT_EQ(s.release.ReleaseName(2), "v3");
  EXPECT_EQ(s.inputs.size(), 3u);  // scene, blocks, runs
}

// A run table of 100 000 rows took 72 s to load (each run's id compared with every earlier
// one's); 200 000 rows now take about a second, the quadratic check would take minutes.
TEST(LoadScene, ALargeRunTableLoadsInTimeInProportion) {
  const auto dir = testing::FreshDir("runs_large");
  std::string runs = "trajectory_id,x_m,y_m\n";
  for (int k = 0; k < 200000; ++k) runs.append("r").append(std::to_string(k)).append(",5,0\n");
  testing::WriteText(dir / "runs.csv", runs);
  testing::WriteText(dir / "scene.toml",
                     "[terrain]\nplane = { slope_deg = 35, slope_length_m = 40, runout_m = 20, "
                     "width_m = 30, cell_m = 1 }\n[rock]\nshape = { box = [0.5, 0.4, 0.3] }\n"
                     "[release]\nruns = \"runs.csv\"\nrocks = 1\n");
  const auto t0 = std::chrono::steady_clock::now();
  const SceneFile s = LoadScene((dir / "scene.toml").string());
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_EQ(s.release.runs.size(), 200000u);
  EXPECT_LT(seconds, 60.0);  // a wide margin for sanitizer builds and loaded machines
}

TEST(LoadScene, RunTableErrorsNameFileLineAndColumn) {
  const auto dir = testing::FreshDir("runs_bad");
  testing::WriteText(dir / "blocks.csv", kBlocksCsv);
  const auto error = [&](const std::string& runs, const std::string& scene = kRunScene) {
    testing::WriteText(dir / "runs.csv", runs);
    return ErrorOf(scene, dir);
  };
  EXPECT_HAS(error("trajectory_id,x_m\nv1,5\n"), "runs.csv: missing column 'y_m'");
  EXPECT_HAS(error("trajectory_id,x_m,y_m\nv1,5,abc\n"),
             "runs.csv:2: column 'y_m': 'abc' is not a finite number");
  EXPECT_HAS(error("trajectory_id,x_m,y_m,block_id\nv1,5,0,1\nv1,6,0,1\n"),
             "runs.csv:3: column 'trajectory_id': run 'v1' appears twice");
  EXPECT_HAS(error("trajectory_id,x_m,y_m,block_id\nv1,5,0,9\n"),
             "runs.csv:2: column 'block_id': unknown block '9' (known: 1, 4, slab)");
  EXPECT_HAS(error("trajectory_id,x_m,y_m,block_id\nv1,500,0,1\n"),
             "runs.csv:2: column 'x_m': (500, 0) is outside the DEM");
  EXPECT_HAS(error("trajectory_id,x_m,y_m,block_id\nv1,5,0\n"), "runs.csv:2: 3 fields");
  EXPECT_HAS(error("trajectory_id,x_m,y_m\nv1,5,0\n"),
             "a run without a block needs the scene's [rock]");
  EXPECT_HAS(error("trajectory_id,x_m,y_m,block_id\nv1,5,0,1\n",
                   Replace(kRunScene, "shape = \"box\"", "shape = \"cube\"")),
             "blocks.shape: 'cube': expected \"box\", \"ellipsoid\", \"rock\", \"eota111\" or "
             "\"eota221\"");
  EXPECT_HAS(error("trajectory_id,x_m,y_m,block_id\nv1,5,0,1\n",
                   Replace(kRunScene, "rocks = 3", "rocks = 3\npoints = [[1, 1]]")),
             "release.runs: a run table cannot be combined with points");
  EXPECT_HAS(error("trajectory_id,x_m,y_m,block_id\nv1,5,0,1\n",
                   Replace(kRunScene, "rocks = 3", "rocks = 3\nvelocity_m_s = [1, 0, 0]")),
             "release.velocity_m_s: a run table gives each run's start velocities");
  testing::WriteText(dir / "blocks.csv",
                     "block_id,mass_kg,size_x_m,size_y_m,size_z_m\n1,69,0,1,1\n");
  EXPECT_HAS(error("trajectory_id,x_m,y_m,block_id\nv1,5,0,1\n"),
             "blocks.csv:2: column 'size_x_m': must be > 0");
}

// The Chant Sura layout: no block_id column; runs name their block by the text of mass_kg, and
// the blocks are EOTA blocks of given bounding box and mass (the bevel gives the volume).
const char* kMassBlockScene = R"([terrain]
plane = { slope_deg = 35, slope_length_m = 40, runout_m = 20, width_m = 30, cell_m = 1 }

[blocks]
shape = "eota221"
density_kg_m3 = 2670

[blocks."210"]
size_m = [0.606, 0.606, 0.303]
mass_kg = 210

[blocks."250"]
shape = "eota111"
size_m = [0.509, 0.509, 0.509]
mass_kg = 250

[blocks."780"]
size_m = [0.93, 0.93, 0.47]
mass_kg = 780

[release]
runs = "runs.csv"
block_column = "mass_kg"
rocks = 2
)";

TEST(LoadScene, RunsNameBlocksByAnotherColumnAndBlocksAreEota) {
  const auto dir = testing::FreshDir("mass_blocks");
  testing::WriteText(dir / "runs.csv",
                     "trajectory_id,x_m,y_m,z_m,mass_kg,radius_m\n"
                     "a_seg00,5,0,,210,0.266\n"
                     "a_seg01,6,0,,780,0.412\n"
                     "b_seg00,7,0,,250,0.282\n");
  testing::WriteText(dir / "scene.toml", kMassBlockScene);
  const SceneFile s = LoadScene((dir / "scene.toml").string());
  ASSERT_EQ(s.release.runs.size(), 3u);
  const auto block_of = [&](int run) {
    return s.release
        .blocks[static_cast<std::size_t>(s.release.runs[static_cast<std::size_t>(run)].block)];
  };
  EXPECT_EQ(block_of(0).id, "210");
  EXPECT_EQ(block_of(1).id, "780");
  EXPECT_EQ(block_of(2).id, "250");
  // Mass kept; the bevel chosen for the volume mass / density inside the given bounding box.
  for (int run = 0; run < 3; ++run) {
    const RockShape& rock = *block_of(run).shape;
    const double mass_kg = std::stod(block_of(run).id);
    EXPECT_NEAR(rock.mass_kg, mass_kg, 1e-6 * mass_kg);
    EXPECT_NEAR(rock.volume_m3, mass_kg / 2670, 1e-6 * mass_kg / 2670);
    EXPECT_EQ(rock.vertices_m.size(), 24u);  // a box with all twelve edges bevelled
  }
  EXPECT_EQ(s.block_specs[0].builtin, "eota221");
  EXPECT_EQ(s.block_specs[1].builtin, "eota111");  // the block's own shape over [blocks]'
  // The EOTA111 is a cube: equal principal moments; the EOTA221 is not.
  const RockShape& cube = *block_of(2).shape;
  EXPECT_NEAR(cube.inertia_kg_m2.minCoeff(), cube.inertia_kg_m2.maxCoeff(),
              1e-9 * cube.inertia_kg_m2.maxCoeff());
  const RockShape& wheel = *block_of(1).shape;
  EXPECT_GT(wheel.inertia_kg_m2.maxCoeff(), 1.3 * wheel.inertia_kg_m2.minCoeff());
}

TEST(LoadScene, BlockColumnAndEotaBlockErrorsNameFileLineAndKey) {
  const auto dir = testing::FreshDir("mass_blocks_bad");
  const auto error = [&](const std::string& runs, const std::string& scene = kMassBlockScene) {
    testing::WriteText(dir / "runs.csv", runs);
    return ErrorOf(scene, dir);
  };
  const std::string runs = "trajectory_id,x_m,y_m,mass_kg\na,5,0,210\n";
  // The column is the block's name as text: 210.0 is not block "210".
  EXPECT_HAS(error("trajectory_id,x_m,y_m,mass_kg\na,5,0,210\nb,5,0,210.0\n"),
             "runs.csv:3: column 'mass_kg': unknown block '210.0' (known: 210, 250, 780)");
  EXPECT_HAS(error("trajectory_id,x_m,y_m,block_id\na,5,0,210\n"),
             "scene.toml:23: release.block_column: ");
  EXPECT_HAS(error("trajectory_id,x_m,y_m,block_id\na,5,0,210\n"),
             "runs.csv: missing column 'mass_kg'");
  EXPECT_HAS(
      error(runs, Replace(kMassBlockScene, "block_column = \"mass_kg\"", "block_column = \"\"")),
      "scene.toml:23: release.block_column: empty");
  EXPECT_HAS(error(runs, Replace(kMassBlockScene, "block_column", "block_colum")),
             "release.block_colum: unknown key (did you mean 'block_column'?)");
  EXPECT_HAS(error(runs, Replace(kMassBlockScene, "shape = \"eota111\"", "shape = \"eota112\"")),
             "scene.toml:13: blocks.250.shape: 'eota112': expected \"box\"");
  // 780 kg of density 2670 do not fit a 0.5 m cube: no bevel reaches that volume.
  EXPECT_HAS(error(runs, Replace(kMassBlockScene, "[0.93, 0.93, 0.47]", "[0.5, 0.5, 0.5]")),
             "scene.toml:17: blocks.780: eota221: no bevel gives a volume of");
  // A table file may give each block's shape too.
  testing::WriteText(dir / "blocks.csv",
                     "block_id,mass_kg,size_x_m,size_y_m,size_z_m,shape\n9,10,1,1,1,eota333\n");
  EXPECT_HAS(error(runs, Replace(kMassBlockScene, "density_kg_m3 = 2670",
                                 "density_kg_m3 = 2670\nfile = \"blocks.csv\"")),
             "blocks.csv:2: column 'shape': 'eota333': expected");
  EXPECT_HAS(error(runs, Replace(kMassBlockScene, "density_kg_m3 = 2670",
                                 "density_kg_m3 = 2670\nroughness = 0.2")),
             "blocks.roughness: only rock blocks take points and roughness");
}

TEST(LoadScene, ShapePerRockNeedsRockShapes) {
  const auto dir = testing::FreshDir("per_rock");
  testing::WriteText(dir / "blocks.csv", kBlocksCsv);
  testing::WriteText(dir / "runs.csv", "trajectory_id,x_m,y_m,block_id\nv1,5,0,1\n");
  EXPECT_HAS(
      ErrorOf(Replace(kRunScene, "shape = \"box\"", "shape = \"box\"\nshape_per_rock = true"), dir),
      "only rock blocks have a shape of their own per rock");
  testing::WriteText(dir / "scene.toml", Replace(kRunScene, "shape = \"box\"",
                                                 "shape = \"rock\"\nshape_per_rock = true"));
  const SceneFile s = LoadScene((dir / "scene.toml").string());
  ASSERT_TRUE(static_cast<bool>(s.release.shape_per_rock));
  const RockShape a = s.release.shape_per_rock(&s.release.blocks[0], 1),
                  b = s.release.shape_per_rock(&s.release.blocks[0], 2);
  EXPECT_NEAR(a.mass_kg, 69, 1e-9);  // size and mass kept, whatever the seed
  EXPECT_NEAR(b.mass_kg, 69, 1e-9);
  EXPECT_NE(a.vertices_m.size() == b.vertices_m.size() && a.vertices_m[0] == b.vertices_m[0], true);
}

// Shape per block: each rock block its own roughness, points and seed (in [blocks.<id>] or as
// columns of the blocks file), a scanned point cloud as a block (`file`), and the knobs a
// calibration may change recorded with a maker that rebuilds the block from them.
TEST(LoadScene, EachBlockHasAShapeOfItsOwn) {
  const auto dir = testing::FreshDir("block_shapes");
  testing::WriteText(
      dir / "blocks.csv",
      "block_id,mass_kg,size_x_m,size_y_m,size_z_m,roughness,points,shape_seed,file\n"
      "1,69,0.37,0.32,0.37,0.3,40,7,\n"
      "4,40,0.46,0.30,0.20,,,,\n"
      "scan,,,,,,,,cube.xyz\n");
  // The corners of a 0.4 m cube and its centre: the hull is the cube.
  std::string cube;
  for (int i = 0; i < 8; ++i)
    cube += std::to_string(0.4 * (i & 1)) + " " + std::to_string(0.4 * ((i >> 1) & 1)) + " " +
            std::to_string(0.4 * ((i >> 2) & 1)) + "\n";
  testing::WriteText(dir / "cube.xyz", cube + "0.2 0.2 0.2\n");
  testing::WriteText(dir / "runs.csv", "trajectory_id,x_m,y_m,block_id\nv1,5,0,1\nv2,5,1,slab\n");
  const std::string scene = Replace(Replace(kRunScene, "shape = \"box\"", "shape = \"rock\""),
                                    "mass_kg = 250", "mass_kg = 250\nroughness = 0.05");
  testing::WriteText(dir / "scene.toml", scene);
  const SceneFile s = LoadScene((dir / "scene.toml").string());
  ASSERT_EQ(s.release.blocks.size(), 4u);
  const ensemble::Block& first = s.release.blocks[0];
  EXPECT_EQ(first.id, "1");
  EXPECT_EQ(first.knobs.roughness, 0.3);
  EXPECT_EQ(first.knobs.shape_seed, 7u);
  EXPECT_EQ(first.knobs.size_m, Eigen::Vector3d(0.37, 0.32, 0.37));
  EXPECT_EQ(s.block_specs[0].points, 40);
  EXPECT_NEAR(first.shape->mass_kg, 69, 1e-9);
  EXPECT_EQ(s.release.blocks[1].knobs.roughness, 0.15);  // [blocks]' default
  EXPECT_EQ(s.release.blocks[3].id, "slab");
  EXPECT_EQ(s.release.blocks[3].knobs.roughness, 0.05);
  // The maker gives the block back from its knobs, and another block from other knobs.
  ASSERT_TRUE(static_cast<bool>(first.make));
  const RockShape again = first.make(first.knobs);
  ASSERT_EQ(again.vertices_m.size(), first.shape->vertices_m.size());
  EXPECT_EQ(again.vertices_m[0], first.shape->vertices_m[0]);
  ensemble::ShapeKnobs smoother = first.knobs;
  smoother.roughness = 0;
  EXPECT_NE(first.make(smoother).vertices_m[0], first.shape->vertices_m[0]);
  EXPECT_NEAR(first.make(smoother).mass_kg, 69, 1e-9);  // the mass stays
  // The scanned block: its hull, no knobs, no maker; the file is an input of the scene.
  const ensemble::Block& scan = s.release.blocks[2];
  EXPECT_EQ(scan.shape->vertices_m.size(), 8u);
  EXPECT_NEAR(scan.shape->volume_m3, 0.064, 1e-12);
  EXPECT_FALSE(static_cast<bool>(scan.make));
  EXPECT_TRUE(std::isnan(scan.knobs.roughness));
  EXPECT_FALSE(scan.knobs.size_m.allFinite());
  EXPECT_NE(std::find(s.inputs.begin(), s.inputs.end(), (dir / "cube.xyz").string()),
            s.inputs.end());
}

TEST(LoadScene, BlockShapeKnobsAreChecked) {
  const auto dir = testing::FreshDir("block_shape_errors");
  testing::WriteText(dir / "blocks.csv", kBlocksCsv);
  testing::WriteText(dir / "runs.csv", "trajectory_id,x_m,y_m,block_id\nv1,5,0,1\n");
  testing::WriteText(dir / "cube.xyz", "0 0 0\n1 0 0\n0 1 0\n0 0 1\n1 1 1\n");
  EXPECT_HAS(ErrorOf(Replace(kRunScene, "mass_kg = 250", "mass_kg = 250\nroughness = 0.1"), dir),
             "block 'slab': roughness: only a rock block has a roughness");
  EXPECT_HAS(ErrorOf(Replace(Replace(kRunScene, "shape = \"box\"", "shape = \"rock\""),
                             "mass_kg = 250", "mass_kg = 250\nroughness = 0.7"),
                     dir),
             "block 'slab': roughness: 0.7 must be in 0 .. 0.5");
  EXPECT_HAS(ErrorOf(Replace(kRunScene, "size_m = [1.0, 0.5, 0.2]",
                             "file = \"cube.xyz\"\nsize_m = [1, 1, 1]"),
                     dir),
             "blocks.slab.size_m: a point cloud block takes its shape and size from its file");
  EXPECT_HAS(ErrorOf(Replace(kRunScene, "size_m = [1.0, 0.5, 0.2]", "file = \"missing.xyz\""), dir),
             "file not found");
  EXPECT_HAS(
      ErrorOf(Replace(kRunScene, "shape = \"box\"", "shape = \"rock\"\nsize_variation = 0.1"), dir),
      "blocks.size_variation: varies the shape per rock: needs shape_per_rock = true");
  testing::WriteText(dir / "blocks.csv",
                     "block_id,size_x_m,size_y_m,size_z_m,file\n1,0.3,0.3,0.3,cube.xyz\n");
  EXPECT_HAS(ErrorOf(kRunScene, dir),
             "blocks.csv:2: column 'size_x_m': a point cloud block takes its shape and size from "
             "the file");
}

// size_variation: the axes of each rock's shape vary about the block's within exp(+-4a/3) of
// their ratios while the product of the axes, and with it the block's mass, stays; the draws
// depend on the rock's shape seed only.
TEST(LoadScene, ShapeVariationPerRockKeepsTheMassAndBoundsTheAxes) {
  const auto dir = testing::FreshDir("shape_variation");
  testing::WriteText(dir / "blocks.csv", kBlocksCsv);
  testing::WriteText(dir / "runs.csv", "trajectory_id,x_m,y_m,block_id\nv1,5,0,1\n");
  testing::WriteText(dir / "scene.toml",
                     Replace(kRunScene, "shape = \"box\"",
                             "shape = \"rock\"\nshape_per_rock = true\nsize_variation = 0.2"));
  const SceneFile s = LoadScene((dir / "scene.toml").string());
  const ensemble::Block& block = s.release.blocks[0];
  const Eigen::Vector3d size = block.knobs.size_m;
  double spread = 0;
  for (std::uint64_t seed = 1; seed <= 20; ++seed) {
    const ensemble::ShapeKnobs k = VariedKnobs(block.knobs, s.shape_variation, seed);
    EXPECT_NEAR(k.size_m.prod(), size.prod(), 1e-12 * size.prod());
    for (int i = 0; i < 3; ++i) {
      EXPECT_LE(std::abs(std::log(k.size_m[i] / size[i])), 4 * 0.2 / 3 + 1e-12);
      spread = std::max(spread, std::abs(std::log(k.size_m[i] / size[i])));
    }
    // The rock's own shape is the block's made from these knobs with the rock's seed.
    const RockShape rock = s.release.shape_per_rock(&block, seed);
    EXPECT_NEAR(rock.mass_kg, 69, 1e-9);
    ensemble::ShapeKnobs seeded = k;
    seeded.shape_seed = seed;
    const RockShape made = block.make(seeded);
    ASSERT_EQ(rock.vertices_m.size(), made.vertices_m.size());
    for (std::size_t v = 0; v < made.vertices_m.size(); ++v)
      EXPECT_EQ(rock.vertices_m[v], made.vertices_m[v]);
  }
  EXPECT_GT(spread, 0.1);  // the draws do vary
  EXPECT_NE(VariedKnobs(block.knobs, s.shape_variation, 1).size_m,
            VariedKnobs(block.knobs, s.shape_variation, 2).size_m);
}

// A run table's surveyed ground height (ground_z_m) is compared with the DEM's at each start: the
// plane is 35 degrees down x from height 40 * tan(35 deg) at x = 0 (its 40 m slope), so at x = 5
// the ground is 35 * tan(35 deg) = 24.507 m. A run 2 m off is listed and warned of once; one 0.3 m
// off is not (tolerance 1 m by default; 0.2 m lists both).
TEST(LoadScene, StartsOffTheSurveyedGroundAreListedAndWarned) {
  const auto dir = testing::FreshDir("ground_z");
  testing::WriteText(dir / "blocks.csv", kBlocksCsv);
  const double ground = 35 * std::tan(35 * M_PI / 180);
  testing::WriteText(dir / "runs.csv", "trajectory_id,x_m,y_m,block_id,ground_z_m\nv1,5,0,1," +
                                           std::to_string(ground + 0.3) + "\nv2,5,1,1," +
                                           std::to_string(ground - 2) + "\nv3,5,2,1,\n");
  testing::WriteText(dir / "scene.toml", kRunScene);
  const SceneFile s = LoadScene((dir / "scene.toml").string());
  ASSERT_EQ(s.ground_mismatches.size(), 1u);
  EXPECT_EQ(s.ground_mismatches[0].run, "v2");
  EXPECT_NEAR(s.ground_mismatches[0].dem_z_m, ground, 1e-6);
  EXPECT_NEAR(s.ground_mismatches[0].surveyed_z_m, ground - 2, 1e-5);
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_HAS(s.warnings[0], "1 of 3 runs start where the DEM departs from the surveyed ground");
  EXPECT_HAS(s.warnings[0], "largest: run 'v2'");
  testing::WriteText(dir / "scene.toml",
                     Replace(kRunScene, "rocks = 3", "rocks = 3\nground_z_tolerance_m = 0.2"));
  EXPECT_EQ(LoadScene((dir / "scene.toml").string()).ground_mismatches.size(), 2u);
  EXPECT_HAS(ErrorOf(Replace(kRunScene, "rocks = 3", "rocks = 3\nground_z_tolerance_m = 0"), dir),
             "release.ground_z_tolerance_m: 0 must be in (0, 1000] m");
  testing::WriteText(dir / "runs.csv", "trajectory_id,x_m,y_m,block_id\nv1,5,0,1\n");
  EXPECT_HAS(ErrorOf(Replace(kRunScene, "rocks = 3", "rocks = 3\nground_z_tolerance_m = 2"), dir),
             "release.ground_z_tolerance_m: the run table has no ground_z_m column to compare");
  EXPECT_HAS(ErrorOf("[terrain]\nplane = {}\n[rock]\nshape = { box = [1, 1, 1] }\n[release]\n"
                     "points = [[10, 0]]\nground_z_tolerance_m = 2\n",
                     dir),
             "release.ground_z_tolerance_m: compares a run table's ground_z_m with the DEM");
}

// Reliability item 4: inputs that used to be accepted without a word and give wrong results.

// A DEM in degrees would be read as metres: slopes of thousands of kilometres per cell.
TEST(LoadScene, DemInAGeographicCrsIsAnError) {
  const auto dir = testing::FreshDir("dem_wgs84");
  std::filesystem::create_directories(dir / "data");
  testing::WriteGdalRaster(dir / "data" / "dem.tif",
                           std::vector<std::vector<double>>(7, std::vector<double>(7, 500.0)),
                           {11.0, 0.001, 0.0, 47.0, 0.0, -0.001}, 4326, -9999.0);
  const std::string e = ErrorOf(
      "[terrain]\ndem = \"data/dem.tif\"\n[rock]\nshape = { sphere = 0.3 }\n"
      "[release]\npoints = [[11.003, 46.997]]\n",
      dir);
  EXPECT_HAS(e, "scene.toml:2: terrain.dem: " + (dir / "data" / "dem.tif").string() +
                    " is in a geographic CRS (degrees); Talus needs a projected CRS in metres: "
                    "reproject it (e.g. gdalwarp -t_srs EPSG:32632");
}

// 1e30 is a common undeclared nodata value; heights in mm are another mistake.
TEST(LoadScene, DemHeightsBeyondTwentyKilometresAreErrors) {
  const auto dir = testing::FreshDir("dem_huge");
  std::filesystem::create_directories(dir / "data");
  std::vector<std::vector<double>> dem(5, std::vector<double>(6, 500.0));
  dem[0][2] = 1e30;  // no nodata declared
  testing::WriteGdalRaster(dir / "data" / "dem.tif", dem, kGeo, 31287, std::nullopt);
  const std::string scene =
      "[terrain]\ndem = \"data/dem.tif\"\n[rock]\nshape = { sphere = 0.3 }\n"
      "[release]\npoints = [[1015, 2015]]\n";
  EXPECT_HAS(ErrorOf(scene, dir),
             "scene.toml:2: terrain.dem: " + (dir / "data" / "dem.tif").string() +
                 " has the height 1e+30 m (cell 2, 4 from the south-west), "
                 "beyond +-20000 m");
  // An infinite height is not silently nodata either.
  dem[0][2] = -std::numeric_limits<double>::infinity();
  testing::WriteGdalRaster(dir / "data" / "dem.tif", dem, kGeo, 31287, std::nullopt);
  EXPECT_HAS(ErrorOf(scene, dir), "has the height -inf m (cell 2, 4 from the south-west)");
  dem[0][2] = -20001;
  testing::WriteGdalRaster(dir / "data" / "dem.tif", dem, kGeo, 31287, std::nullopt);
  EXPECT_HAS(ErrorOf(scene, dir), "has the height -20001 m");
  dem[0][2] = 8848;
  testing::WriteGdalRaster(dir / "data" / "dem.tif", dem, kGeo, 31287, std::nullopt);
  EXPECT_EQ(ErrorOf(scene, dir), "");
}

// A ground map of another site used to give the default ground everywhere, silently.
TEST(LoadScene, GroundRasterOffTheDemIsAnError) {
  const auto dir = testing::FreshDir("ground_off");
  WriteDemCase(dir);
  testing::WriteGdalRaster(dir / "data" / "ground_far.tif", {{6, 6}, {6, 6}},
                           {5000.0, 20.0, 0.0, 6000.0, 0.0, -20.0}, 31287, 255.0);
  const std::string e =
      ErrorOf(Replace(kDemScene, "\"data/ground.tif\"", "\"data/ground_far.tif\""), dir);
  EXPECT_HAS(e, "scene.toml:3: terrain.ground: " + (dir / "data" / "ground_far.tif").string() +
                    " covers x 5000 .. 5040, y 5960 .. 6000, which does not overlap the DEM "
                    "(x 1005 .. 1055, y 2005 .. 2045)");
  // Touching the DEM's edge only is no overlap either.
  testing::WriteGdalRaster(dir / "data" / "ground_edge.tif", {{6, 6}, {6, 6}},
                           {1055.0, 20.0, 0.0, 2050.0, 0.0, -20.0}, 31287, 255.0);
  EXPECT_HAS(ErrorOf(Replace(kDemScene, "\"data/ground.tif\"", "\"data/ground_edge.tif\""), dir),
             "does not overlap the DEM");
  // Partial overlap is fine: the default ground applies where the map has no cell.
  testing::WriteGdalRaster(dir / "data" / "ground_part.tif", {{6, 6}, {6, 6}},
                           {1040.0, 20.0, 0.0, 2070.0, 0.0, -20.0}, 31287, 255.0);
  testing::WriteText(dir / "scene.toml",
                     Replace(kDemScene, "\"data/ground.tif\"", "\"data/ground_part.tif\""));
  const SceneFile s = LoadScene((dir / "scene.toml").string());
  EXPECT_EQ(s.scene.terrain.GroundAt(1045, 2045), s.scene.ground.IndexOfName("hard"));
  EXPECT_EQ(s.scene.terrain.GroundAt(1005, 2005), s.scene.ground.IndexOfName("medium"));
}

// Finite but absurd values (typos, wrong units) are errors stating the bound.
TEST(LoadScene, AbsurdFiniteValuesAreErrorsStatingTheBound) {
  const auto dir = testing::FreshDir("absurd");
  const auto error = [&](const std::string& from, const std::string& to) {
    return ErrorOf(Replace(kPlaneScene, from, to), dir);
  };
  EXPECT_HAS(error("density_kg_m3 = 2600", "density_kg_m3 = 2.6"),
             "scene.toml:7: rock.density_kg_m3: 2.6 is outside 100 .. 30000 kg/m3");
  EXPECT_HAS(error("density_kg_m3 = 2600", "density_kg_m3 = 2600000"),
             "rock.density_kg_m3: 2600000 is outside 100 .. 30000 kg/m3");
  const std::string eota = "shape = { box = [0.5, 0.4, 0.3] }\ndensity_kg_m3 = 2600";
  EXPECT_HAS(error(eota, "shape = { eota = \"221\" }\nvolume_m3 = 1e-12"),
             "scene.toml:7: rock.volume_m3: 1e-12 is outside 1e-09 .. 1000000 m3");
  EXPECT_HAS(error(eota, "shape = { eota = \"221\" }\nvolume_m3 = 2e6"),
             "rock.volume_m3: 2000000 is outside 1e-09 .. 1000000 m3");
  EXPECT_HAS(error("box = [0.5, 0.4, 0.3]", "box = [500, 400, 300]"),
             "scene.toml:6: rock.shape: the rock's volume 60000000 is outside 1e-09 .. 1000000 m3");
  EXPECT_HAS(error("velocity_m_s = [1, 0, 0]", "velocity_m_s = [300, 0, 400]"),
             "scene.toml:16: release.velocity_m_s: |v| = 500 m/s is more than 200 m/s");
  EXPECT_HAS(error("angular_velocity_rad_s = [0, 0, 1]", "angular_velocity_rad_s = [0, 0, 2000]"),
             "scene.toml:17: release.angular_velocity_rad_s: |v| = 2000 rad/s is more than 1000 "
             "rad/s");
  EXPECT_HAS(error("height_m = 1.5", "height_m = 15000"),
             "scene.toml:14: release.height_m: 15000 is more than 10000 m");
  EXPECT_HAS(error("max_time_s = 20", "max_time_s = 20\ngravity_m_s2 = 981"),
             "scene.toml:23: solver.gravity_m_s2: 981 is outside 0.1 .. 100 m/s2");
  EXPECT_HAS(error("max_time_s = 20", "max_time_s = 20\ngravity_m_s2 = 0"),
             "solver.gravity_m_s2: 0 is outside 0.1 .. 100 m/s2");
  // The bounds themselves are accepted.
  EXPECT_EQ(error("max_time_s = 20", "max_time_s = 20\ngravity_m_s2 = 0.1"), "");
  EXPECT_EQ(error("velocity_m_s = [1, 0, 0]", "velocity_m_s = [200, 0, 0]"), "");
  EXPECT_EQ(error("height_m = 1.5", "height_m = 10000"), "");
}

TEST(LoadScene, AbsurdRunTableAndBlockValuesAreErrorsStatingTheBound) {
  const auto dir = testing::FreshDir("absurd_runs");
  testing::WriteText(dir / "blocks.csv", kBlocksCsv);
  const auto error = [&](const std::string& runs, const std::string& scene = kRunScene) {
    testing::WriteText(dir / "runs.csv", runs);
    return ErrorOf(scene, dir);
  };
  EXPECT_HAS(error("trajectory_id,x_m,y_m,block_id,vx_mps,vy_mps\nv1,5,0,1,0,250\n"),
             "runs.csv:2: column 'vy_mps': start velocity |v| = 250 m/s is more than 200 m/s");
  EXPECT_HAS(error("trajectory_id,x_m,y_m,block_id,wz_radps\nv1,5,0,1,1e4\n"),
             "runs.csv:2: column 'wz_radps': start angular velocity |v| = 10000 rad/s is more "
             "than 1000 rad/s");
  EXPECT_HAS(error("trajectory_id,x_m,y_m,block_id,height_m\nv1,5,0,1,20000\n"),
             "runs.csv:2: column 'height_m': 20000 is more than 10000 m");
  EXPECT_HAS(error("trajectory_id,x_m,y_m,block_id,z_m\nv1,5,0,1,20000\n"),
             "runs.csv:2: column 'z_m': 20000 m is ");
  const std::string ok = "trajectory_id,x_m,y_m,block_id\nv1,5,0,1\n";
  EXPECT_EQ(error(ok), "");
  EXPECT_HAS(
      error(ok, Replace(kRunScene, "shape = \"box\"", "shape = \"box\"\ndensity_kg_m3 = 50")),
      "scene.toml:7: blocks.density_kg_m3: 50 is outside 100 .. 30000 kg/m3");
  EXPECT_HAS(
      error(ok, Replace(kRunScene, "size_m = [1.0, 0.5, 0.2]", "size_m = [1e-4, 1e-4, 1e-4]")),
      "blocks.slab: block 'slab': the volume 1e-12 is outside 1e-09 .. 1000000 m3");
}

// clip_to_dem: a polygon half over a nodata hole starts every rock on valid terrain and keeps
// its rock count; without the option the release is an error, and a point off the DEM or a
// polygon entirely over nodata stays one.
TEST(LoadScene, ClipToDemStartsRocksOnlyOverValidCells) {
  const auto dir = testing::FreshDir("clip");
  std::filesystem::create_directories(dir / "data");
  // 7 x 7 nodes of 10 m at the pixel centres (x 1005 .. 1065, y 1985 .. 2045); the nodes from
  // x = 1035 east are nodata, so the terrain east of x = 1025 has no height.
  std::vector<std::vector<double>> dem(7, std::vector<double>(7, 500.0));
  for (auto& row : dem)
    for (int c = 3; c < 7; ++c) row[c] = -9999;
  testing::WriteGdalRaster(dir / "data" / "dem.tif", dem, kGeo, 31287, -9999.0);
  const std::string scene =
      "[terrain]\ndem = \"data/dem.tif\"\n[rock]\nshape = { sphere = 0.3 }\n[release]\n"
      "rocks = 400\n";
  const std::string half =
      "polygons = [[[1010, 1995], [1040, 1995], [1040, 2035], [1010, 2035]]]\n";
  EXPECT_HAS(ErrorOf(scene + half, dir), "is outside the DEM or on nodata");
  EXPECT_HAS(ErrorOf(scene + half, dir), "clip_to_dem = true starts rocks on the rest");

  testing::WriteText(dir / "scene.toml", scene + half + "clip_to_dem = true\n");
  const SceneFile s = LoadScene((dir / "scene.toml").string());
  ASSERT_EQ(s.release.total_rocks(), 400);
  int west_of_hole = 0;
  for (long k = 0; k < s.release.total_rocks(); ++k) {
    const Eigen::Vector3d p = ensemble::Release(s.scene, s.release, k).start.position_m;
    EXPECT_TRUE(ensemble::OnTerrain(s.scene.terrain, p.head<2>())) << k << ": " << p.transpose();
    EXPECT_LE(p.x(), 1025.0) << k;
    EXPECT_GE(p.x(), 1010.0) << k;
    west_of_hole += p.x() < 1025 ? 1 : 0;
  }
  EXPECT_EQ(west_of_hole, 400);
  // The same start points for the same seed (deterministic), and on a line too.
  EXPECT_EQ(ensemble::Release(s.scene, s.release, 7).start.position_m,
            ensemble::Release(LoadScene((dir / "scene.toml").string()).scene, s.release, 7)
                .start.position_m);
  testing::WriteText(dir / "scene.toml",
                     scene + "lines = [[[1010, 2010], [1060, 2010]]]\nclip_to_dem = true\n");
  const SceneFile line = LoadScene((dir / "scene.toml").string());
  for (long k = 0; k < line.release.total_rocks(); ++k)
    EXPECT_LE(ensemble::Release(line.scene, line.release, k).start.position_m.x(), 1025.0);

  EXPECT_HAS(ErrorOf(scene + "points = [[1045, 2010]]\nclip_to_dem = true\n", dir),
             "release.points[0]: (1045, 2010) is outside the DEM or on nodata");
  EXPECT_HAS(
      ErrorOf(scene + "polygons = [[[1040, 1995], [1060, 1995], [1060, 2035], [1040, 2035]]]\n"
                      "clip_to_dem = true\n",
              dir),
      "release.polygons[0]: lies entirely outside the DEM or on nodata");
  EXPECT_HAS(ErrorOf(scene + half + "clip_to_dem = 1\n", dir),
             "release.clip_to_dem: expected true or false");
}

// rocks_per_m2: each polygon gets round(density x area) rocks, so that polygons of different
// areas get the same rocks per m2; rocks_per_cell is the same per DEM cell.
TEST(LoadScene, RocksPerAreaGiveEachPolygonRocksByItsArea) {
  const auto dir = testing::FreshDir("per_area");
  const std::string scene =
      "[terrain]\nplane = { slope_deg = 30, slope_length_m = 40, runout_m = 20, width_m = 30, "
      "cell_m = 2 }\n[rock]\nshape = { sphere = 0.3 }\n[release]\n"
      "polygons = [[[2, -2], [4, -2], [4, 0], [2, 0]], [[10, 0], [18, 0], [18, 4], [10, 4]],"
      " [[20, 0], [20.3, 0], [20.3, 0.3]]]\n";  // 4 m2, 32 m2 and 0.045 m2
  testing::WriteText(dir / "scene.toml", scene + "rocks_per_m2 = 2.5\n");
  const SceneFile s = LoadScene((dir / "scene.toml").string());
  EXPECT_EQ(s.release.RocksOf(0), 10);  // 2.5 x 4
  EXPECT_EQ(s.release.RocksOf(1), 80);  // 2.5 x 32: the same 2.5 rocks per m2
  EXPECT_EQ(s.release.RocksOf(2), 1);   // round(0.1125) = 0, but every polygon gets a rock
  EXPECT_EQ(s.release.total_rocks(), 91);
  EXPECT_EQ(s.release.ReleaseOf(9), 0);
  EXPECT_EQ(s.release.ReleaseOf(10), 1);
  EXPECT_EQ(s.release.ReleaseOf(89), 1);
  EXPECT_EQ(s.release.ReleaseOf(90), 2);
  EXPECT_EQ(s.release.FirstRockOf(2), 90);
  // Each rock starts inside its own polygon.
  EXPECT_GE(ensemble::Release(s.scene, s.release, 10).start.position_m.x(), 10.0);
  EXPECT_LE(ensemble::Release(s.scene, s.release, 9).start.position_m.x(), 4.0);

  // Per cell of 2 x 2 m: 6 rocks per cell are 1.5 per m2.
  testing::WriteText(dir / "scene.toml", scene + "rocks_per_cell = 6\n");
  const SceneFile c = LoadScene((dir / "scene.toml").string());
  EXPECT_EQ(c.release.RocksOf(0), 6);
  EXPECT_EQ(c.release.RocksOf(1), 48);

  EXPECT_HAS(ErrorOf(scene + "rocks = 3\nrocks_per_m2 = 1\n", dir),
             "release.rocks_per_m2: give one of rocks, rocks_per_m2 and rocks_per_cell, not rocks "
             "as well");
  EXPECT_HAS(ErrorOf(scene + "rocks_per_m2 = -1\n", dir), "release.rocks_per_m2: -1 must be > 0");
  EXPECT_HAS(ErrorOf(scene + "points = [[5, 0]]\nrocks_per_m2 = 1\n", dir),
             "rocks by area are for polygons only, but");
  EXPECT_HAS(ErrorOf(scene + "rocks_per_m2 = 1e12\n", dir), "more than 1000000000");
}

// height_reference: the centre of mass, or the lowest hull vertex, height_m above the ground
// below it. A 2 x 1 x 0.5 m box, unrotated, on a 30 deg plane falling to +x: its lowest vertex
// relative to the ground is the uphill bottom one, (-1, *, -0.25) m from the centre, so
// z_centre = ground(x) + h + 0.25 + 1 * tan 30 (plane geometry; exact up to round-off).
TEST(LoadScene, HeightReferenceCentreOfMassOrLowestPoint) {
  const auto dir = testing::FreshDir("height_reference");
  const std::string scene =
      "[terrain]\nplane = { slope_deg = 30, slope_length_m = 40, runout_m = 20, width_m = 30 }\n"
      "[rock]\nshape = { box = [2, 1, 0.5] }\n[release]\npoints = [[10, 0]]\n"
      "orientation = [1, 0, 0, 0]\nheight_m = 1\n";
  const double ground = (40 - 10) * std::tan(30 * M_PI / 180);
  for (const std::string reference : {"", "height_reference = \"centre_of_mass\"\n"}) {
    testing::WriteText(dir / "scene.toml", scene + reference);
    const SceneFile s = LoadScene((dir / "scene.toml").string());
    EXPECT_NEAR(ensemble::Release(s.scene, s.release, 0).start.position_m.z(), ground + 1, 1e-9);
  }
  testing::WriteText(dir / "scene.toml", scene + "height_reference = \"lowest_point\"\n");
  const SceneFile s = LoadScene((dir / "scene.toml").string());
  const ensemble::ReleasedRock r = ensemble::Release(s.scene, s.release, 0);
  EXPECT_NEAR(r.start.position_m.z(), ground + 1 + 0.25 + std::tan(30 * M_PI / 180), 1e-9);
  EXPECT_EQ(r.lift_m, 0);
  EXPECT_HAS(
      ErrorOf(scene + "height_reference = \"lowest_pont\"\n", dir),
      "release.height_reference: unknown reference 'lowest_pont' (did you mean 'lowest_point'?)");
}

}  // namespace
}  // namespace talus::io

namespace talus::io {
namespace {

const char* kLines = R"(
[evaluation_lines]
lines = [[[20, -10], [20, 10]], [[30, -10], [30, 0], [31, 10]]]
names = ["barrier A", "net, lower"]
)";

TEST(LoadScene, EvaluationLinesFromTheSceneAndAVectorFile) {
  const auto dir = testing::FreshDir("lines");
  // A GeoJSON without "crs" is taken as local coordinates on the plane; the multi-line gives two
  // lines, named by their place since the feature has no name.
  testing::WriteText(dir / "barriers.geojson", R"({"type": "FeatureCollection", "features": [
    {"type": "Feature", "properties": {"name": "road"},
     "geometry": {"type": "LineString", "coordinates": [[40, -5], [40, 5]]}},
    {"type": "Feature", "properties": {"name": null},
     "geometry": {"type": "MultiLineString", "coordinates": [[[45, -5], [45, 0]], [[46, 0], [46, 5]]]}}
  ]})");
  testing::WriteText(dir / "scene.toml",
                     std::string(kPlaneScene) + kLines + "file = \"barriers.geojson\"\n");
  const SceneFile s = LoadScene((dir / "scene.toml").string());
  ASSERT_EQ(s.evaluation_lines.size(), 5u);
  const std::vector<std::string> names = {"barrier A", "net, lower", "road", "line4", "line5"};
  for (std::size_t k = 0; k < names.size(); ++k) EXPECT_EQ(s.evaluation_lines[k].name, names[k]);
  EXPECT_EQ(s.evaluation_lines[1].vertices_m.size(), 3u);
  EXPECT_NEAR(s.evaluation_lines[1].length_m(), 10 + std::sqrt(101.0), 1e-12);
  EXPECT_EQ(s.evaluation_lines[3].vertices_m.back(), Eigen::Vector2d(45, 0));
  EXPECT_EQ(s.inputs.back(), (dir / "barriers.geojson").lexically_normal().string());
  // Default names without a name attribute at all; none without the table.
  testing::WriteText(dir / "scene.toml", std::string(kPlaneScene) +
                                             "[evaluation_lines]\nlines = [[[20, -10], [20, "
                                             "10]]]\n");
  EXPECT_EQ(LoadScene((dir / "scene.toml").string()).evaluation_lines[0].name, "line1");
  testing::WriteText(dir / "scene.toml", kPlaneScene);
  EXPECT_TRUE(LoadScene((dir / "scene.toml").string()).evaluation_lines.empty());
}

TEST(LoadScene, EvaluationLineErrorsNameTheKeyAndTheLine) {
  const auto dir = testing::FreshDir("line_errors");
  const std::string scene = std::string(kPlaneScene) + kLines;
  const auto error = [&](const std::string& from, const std::string& to) {
    return ErrorOf(Replace(scene, from, to), dir);
  };
  const std::string lines = "lines = [[[20, -10], [20, 10]], [[30, -10], [30, 0], [31, 10]]]";
  std::string e = error(lines, "lines = [[[20, -10], [20, 10]], [[30, -10]]]");
  EXPECT_HAS(e, "scene.toml:30: evaluation_lines.lines[1]: a line needs at least 2 vertices");
  e = error(lines, "lines = [[[20, -10], [20, 10]], [[30, 1], [30, 1]]]");
  EXPECT_HAS(e, "evaluation_lines.lines[1]: the line has zero length");
  e = error(lines, "lines = [[[20, -10], [20, 10]], [[30, 1], [nan, 1]]]");
  EXPECT_HAS(e, "evaluation_lines.lines[1][1]: expected a list of 2 finite numbers");
  e = error(lines, "lines = [[[20, -10], [20, 10]], [[100, 100], [120, 100]]]");
  EXPECT_HAS(e, "evaluation_lines.lines[1]: the line 'net, lower' lies entirely outside the DEM");
  EXPECT_HAS(e, "the DEM covers x 0 .. 60, y -15 .. 15");
  e = error("\"net, lower\"]", "\"barrier A\"]");
  EXPECT_HAS(e, "evaluation_lines.lines[1]: the name 'barrier A' is also that of ");
  EXPECT_HAS(e, "evaluation_lines.lines[0]; names must be unique");
  e = error("names = [\"barrier A\", \"net, lower\"]", "names = [\"barrier A\"]");
  EXPECT_HAS(e, "evaluation_lines.names: expected a list of 2 names, one per line of 'lines'");
  e = error("names = [\"barrier A\", \"net, lower\"]", "names = [\"barrier A\", \"\"]");
  EXPECT_HAS(e, "evaluation_lines.names: names[1] is empty");
  e = error("names =", "nmes =");
  EXPECT_HAS(e, "evaluation_lines.nmes: unknown key (did you mean 'names'?)");
  e = error("names =", "name_field = \"id\"\nnames =");
  EXPECT_HAS(e, "evaluation_lines.name_field: only the lines of a vector file");
  e = ErrorOf(std::string(kPlaneScene) + "[evaluation_lines]\n", dir);
  EXPECT_HAS(e, "evaluation_lines.lines: missing: give lines and/or a vector file of lines");
  e = error("names =", "file = \"nowhere.gpkg\"\nnames =");
  EXPECT_HAS(e, "evaluation_lines.file: file not found: ");
  testing::WriteText(dir / "points.geojson", R"({"type": "FeatureCollection", "features": [
    {"type": "Feature", "properties": {"id": "a"},
     "geometry": {"type": "Point", "coordinates": [40, 0]}}]})");
  e = error("names =", "file = \"points.geojson\"\nname_field = \"id\"\nnames =");
  EXPECT_HAS(e, "evaluation_lines.file (");
  EXPECT_HAS(e,
             "points.geojson, feature 0): an evaluation line must be a line or multi-line, "
             "not a POINT");
  testing::WriteText(dir / "lines.geojson", R"({"type": "FeatureCollection", "features": [
    {"type": "Feature", "properties": {"id": "a"},
     "geometry": {"type": "LineString", "coordinates": [[40, 0], [41, 0]]}}]})");
  e = error("names =", "file = \"lines.geojson\"\nname_field = \"label\"\nnames =");
  EXPECT_HAS(e, "lines.geojson, feature 0): no attribute 'label'");
}

}  // namespace
}  // namespace talus::io
