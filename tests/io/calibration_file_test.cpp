// Calibration files: the contact-solve tolerance every evaluation runs with ([solver]
// tolerance_m_s), which of the calibration's and the scene's wins, and bad values refused with
// file, line and key before any rock runs.

#include "io/calibration_file.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "common/error.hpp"
#include "test_files.hpp"

namespace talus::io {
namespace {

// In `dir` (with scene.toml and its four runs r1 .. r4): the observed run-outs, the event, and a
// calibration file freeing medium_soft's mu_min, ending with `tail`; returns the calibration file.
std::string WriteEventAndCalibration(const std::filesystem::path& dir, const std::string& tail) {
  testing::WriteText(dir / "observed.csv",
                     "trajectory_id,observed_runout_m\nr1,17\nr2,19\nr3,14\nr4,16\n");
  testing::WriteText(dir / "event.toml",
                     "scene = \"scene.toml\"\n[[observations]]\nkind = \"runout\"\n"
                     "file = \"observed.csv\"\n");
  testing::WriteText(dir / "cal.toml", R"(event = "event.toml"
[[parameters]]
category = "medium_soft"
field = "mu_min"
lower = 0.1
upper = 0.9
)" + tail);
  return (dir / "cal.toml").string();
}

// A plane scene whose [solver] table is `solver`, four runs with observed run-outs, and a
// calibration file of that event ending with `calibration_tail`; returns the calibration file.
std::string MakeCalibration(const std::string& name, const std::string& solver,
                            const std::string& calibration_tail) {
  const auto dir = testing::FreshDir(name);
  testing::WriteText(dir / "scene.toml", R"([terrain]
plane = { slope_deg = 35, slope_length_m = 20, runout_m = 10, width_m = 12, cell_m = 1 }
default_ground = "medium_soft"
[rock]
shape = { box = [0.4, 0.4, 0.3] }
[release]
runs = "runs.csv"
rocks = 4
[solver]
max_time_s = 3
)" + solver);
  testing::WriteText(dir / "runs.csv",
                     "trajectory_id,x_m,y_m,height_m\nr1,3,0,1\nr2,3,2,1\nr3,4,-2,1\nr4,4,3,1\n");
  return WriteEventAndCalibration(dir, calibration_tail);
}

std::string ErrorOf(const std::string& path) {
  try {
    LoadCalibration(path);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// Neither file sets it: 1e-7 m/s, whatever the scene's preset (the simulations' default and the
// `fast` preset are looser).
TEST(LoadCalibration, ToleranceDefaultsToTheTightSolve) {
  for (const std::string preset : {"", "preset = \"fast\"\n", "preset = \"accurate\"\n"}) {
    const CalibrationFile file = LoadCalibration(MakeCalibration("default", preset, ""));
    EXPECT_EQ(file.objective.tolerance_m_s, calibration::kCalibrationTolerance_m_s) << preset;
    EXPECT_EQ(file.tolerance_source, "default");
  }
}

// The scene's own [solver] tolerance_m_s counts when it is tighter than 1e-7 m/s; a looser one is
// for the scene's simulations and is not used.
TEST(LoadCalibration, TheTighterOfTheScenesToleranceAndTheDefault) {
  const CalibrationFile looser =
      LoadCalibration(MakeCalibration("looser", "tolerance_m_s = 1e-3\n", ""));
  EXPECT_EQ(looser.objective.tolerance_m_s, 1e-7);
  EXPECT_EQ(looser.tolerance_source, "default");
  const CalibrationFile tighter =
      LoadCalibration(MakeCalibration("tighter", "tolerance_m_s = 1e-9\n", ""));
  EXPECT_EQ(tighter.objective.tolerance_m_s, 1e-9);
  EXPECT_EQ(tighter.tolerance_source, "scene");
}

// The calibration file's [solver] tolerance_m_s wins over the scene's, looser or tighter, and
// enters the hash that ties a checkpoint to its calibration.
TEST(LoadCalibration, TheCalibrationsToleranceWins) {
  const CalibrationFile loose = LoadCalibration(
      MakeCalibration("loose", "tolerance_m_s = 1e-9\n", "[solver]\ntolerance_m_s = 1e-5\n"));
  EXPECT_EQ(loose.objective.tolerance_m_s, 1e-5);
  EXPECT_EQ(loose.tolerance_source, "calibration file");
  const CalibrationFile tight = LoadCalibration(
      MakeCalibration("tight", "tolerance_m_s = 1e-3\n", "[solver]\ntolerance_m_s = 1e-8\n"));
  EXPECT_EQ(tight.objective.tolerance_m_s, 1e-8);
  const CalibrationFile plain = LoadCalibration(MakeCalibration("plain", "", ""));
  EXPECT_NE(loose.path_hash, plain.path_hash);
  const CalibrationFile same =
      LoadCalibration(MakeCalibration("same", "", "[solver]\ntolerance_m_s = 1e-7\n"));
  EXPECT_EQ(same.path_hash, plain.path_hash);
}

TEST(LoadCalibration, BadTolerancesAreRefusedNamingFileLineAndKey) {
  const struct {
    std::string value, reason;
  } cases[] = {
      {"0", "0 must be in (0, 1) m/s (the contact solve's tolerance of every evaluation)"},
      {"-1e-7", "-1e-07 must be in (0, 1) m/s (the contact solve's tolerance of every evaluation)"},
      {"1", "1 must be in (0, 1) m/s (the contact solve's tolerance of every evaluation)"},
      {"nan", "nan must be in (0, 1) m/s (the contact solve's tolerance of every evaluation)"},
      {"inf", "inf must be in (0, 1) m/s (the contact solve's tolerance of every evaluation)"},
      {"\"tight\"", "expected a number"},
  };
  for (const auto& c : cases) {
    const std::string path =
        MakeCalibration("bad", "", "[solver]\ntolerance_m_s = " + c.value + "\n");
    EXPECT_EQ(ErrorOf(path), path + ":8: solver.tolerance_m_s: " + c.reason);
  }
  const std::string path = MakeCalibration("unknown", "", "[solver]\ndt_s = 0.001\n");
  EXPECT_EQ(ErrorOf(path).rfind(path + ":8: solver.dt_s: unknown key", 0), 0u) << ErrorOf(path);
}

// Shape parameters: [[parameters]] with `block` instead of `category` frees a knob of a block's
// shape (docs/calibration.md); a block that is not in the scene, a knob the block has not, an
// unknown knob, or both a category and a block are refused naming the file, line and key.
std::string MakeShapeCalibration(const std::string& name, const std::string& parameter) {
  const auto dir = testing::FreshDir(name);
  testing::WriteText(dir / "scene.toml", R"([terrain]
plane = { slope_deg = 35, slope_length_m = 20, runout_m = 10, width_m = 12, cell_m = 1 }
default_ground = "medium_soft"
[blocks]
shape = "rock"
[blocks.round]
size_m = [0.4, 0.4, 0.3]
[blocks.slab]
size_m = [0.5, 0.4, 0.2]
shape = "box"
[release]
runs = "runs.csv"
rocks = 4
[solver]
max_time_s = 3
)");
  testing::WriteText(dir / "runs.csv",
                     "trajectory_id,x_m,y_m,height_m,block_id\nr1,3,0,1,round\nr2,3,2,1,slab\n"
                     "r3,4,-2,1,round\nr4,4,3,1,slab\n");
  return WriteEventAndCalibration(dir, "[[parameters]]\n" + parameter);
}

TEST(LoadCalibration, ShapeParametersNameABlockAndItsKnob) {
  const CalibrationFile file = LoadCalibration(MakeShapeCalibration(
      "shape_ok", "block = \"round\"\nfield = \"roughness\"\nlower = 0\nupper = 0.4\n"));
  ASSERT_EQ(file.parameters.size(), 2u);
  EXPECT_TRUE(file.parameters[1].IsShape());
  EXPECT_EQ(file.parameters[1].Name(), "blocks.round.roughness");
  const CalibrationFile sizes = LoadCalibration(MakeShapeCalibration(
      "shape_size", "block = \"slab\"\nfield = \"size_z_m\"\nlower = 0.15\nupper = 0.25\n"));
  EXPECT_EQ(sizes.parameters[1].Name(), "blocks.slab.size_z_m");

  const std::string unknown = ErrorOf(MakeShapeCalibration(
      "shape_unknown", "block = \"rund\"\nfield = \"roughness\"\nlower = 0\nupper = 0.4\n"));
  EXPECT_NE(unknown.find("cal.toml:8: parameters[1].block: unknown block 'rund' (did you mean "
                         "'round'?); the scene has round, slab"),
            std::string::npos)
      << unknown;
  const std::string no_knob = ErrorOf(MakeShapeCalibration(
      "shape_no_knob", "block = \"slab\"\nfield = \"roughness\"\nlower = 0\nupper = 0.4\n"));
  EXPECT_NE(no_knob.find("blocks.slab.roughness: block 'slab' has no roughness"), std::string::npos)
      << no_knob;
  const std::string field = ErrorOf(MakeShapeCalibration(
      "shape_field", "block = \"round\"\nfield = \"roughnes\"\nlower = 0\nupper = 0.4\n"));
  EXPECT_NE(field.find("parameters[1].field: unknown shape parameter 'roughnes' (did you mean "
                       "'roughness'?)"),
            std::string::npos)
      << field;
  const std::string both = ErrorOf(MakeShapeCalibration(
      "shape_both",
      "category = \"medium_soft\"\nblock = \"round\"\nfield = \"roughness\"\nlower = 0\nupper = "
      "0.4\n"));
  EXPECT_NE(both.find("parameters[1].block: give a ground category or a block, not both"),
            std::string::npos)
      << both;
}

// A parameter's own prior: read in the field's unit; with it, prior_reference defaults to "none"
// (the other parameters stay free); the prior enters the hash that ties a checkpoint to its
// calibration; nonsense is refused naming the file, line and key.
TEST(LoadCalibration, AParametersOwnPriorIsReadAndChecked) {
  const std::string objective = "[objective]\nprior_weight = 0.5\n";
  const CalibrationFile normal = LoadCalibration(
      MakeCalibration("prior", "", "prior = { mean = 0.5, sd = 0.1 }\n" + objective));
  ASSERT_EQ(normal.parameters.size(), 1u);
  ASSERT_TRUE(normal.parameters[0].prior.has_value());
  EXPECT_EQ(normal.parameters[0].prior->mean, 0.5);
  EXPECT_EQ(normal.parameters[0].prior->sd, 0.1);
  EXPECT_EQ(normal.prior_reference, "none");
  EXPECT_FALSE(normal.objective.prior_reference.has_value());
  EXPECT_EQ(normal.objective.prior_weight, 0.5);
  const CalibrationFile wider = LoadCalibration(
      MakeCalibration("prior2", "", "prior = { mean = 0.5, sd = 0.2 }\n" + objective));
  EXPECT_NE(normal.path_hash, wider.path_hash);
  const CalibrationFile log_normal = LoadCalibration(MakeCalibration(
      "prior3", "",
      "prior = { mean = 0.4, factor = 1.5 }\n" + objective + "prior_reference = \"table1\"\n"));
  EXPECT_EQ(log_normal.parameters[0].prior->factor, 1.5);
  EXPECT_TRUE(log_normal.objective.prior_reference.has_value());

  const struct {
    std::string tail, error;
  } bad[] = {
      {"prior = { mean = 0.5, sd = 0.1 }\n",
       ":7: parameters[0].prior: a parameter's prior acts only with [objective] prior_weight > 0"},
      {"prior = { mean = 0.5, sd = 0.1 }\n[objective]\nprior_weight = 0\n",
       ":9: objective.prior_weight: a parameter's prior acts only with [objective] prior_weight > "
       "0"},
      {"prior = { mean = 1.5, sd = 0.1 }\n" + objective,
       ":7: parameters[0].prior: medium_soft.mu_min: prior: mean = 1.5 lies outside the bounds "
       "[0.1, 0.9]"},
      {"prior = { mean = 0.5 }\n" + objective,
       ":7: parameters[0].prior: medium_soft.mu_min: prior: give sd (> 0, a normal prior) or "
       "factor (> 1, a log-normal one), one of them"},
      {"prior = { sd = 0.1 }\n" + objective,
       ":7: parameters[0].prior.mean: missing: the prior's mean, in 1"},
      {"prior = { mean = 0.5, sigma = 0.1 }\n" + objective,
       ":7: parameters[0].prior.sigma: unknown key"},
      {"prior = 0.5\n" + objective, ":7: parameters[0].prior: expected a table"},
      {objective + "prior_reference = \"none\"\n",
       ":9: objective.prior_reference: \"none\" with no parameter's own prior"},
  };
  for (const auto& c : bad) {
    const std::string path = MakeCalibration("prior_bad", "", c.tail);
    const std::string error = ErrorOf(path);
    EXPECT_EQ(error.rfind(path + c.error, 0), 0u) << error;
  }
}

}  // namespace
}  // namespace talus::io
