// End to end through the talus program: `talus calibrate` on a tiny event, and calibration files
// with mistakes, each refused with its file, line, key and reason before any rock runs.

#include <gtest/gtest.h>
#include <signal.h>  // NOLINT(modernize-deprecated-headers): POSIX kill is declared here
#include <sys/wait.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <thread>

#include "run_talus.hpp"
#include "tests/io/older_checkpoint.hpp"

namespace {

namespace fs = std::filesystem;

fs::path FreshDir(const std::string& name) {
  return talus::app::testing::FreshDir("talus_calibrate_tests", name);
}

using talus::app::testing::RunCommand;

using talus::app::testing::Slurp;

using talus::app::testing::Write;

// Four (or seven) runs of a block on a short 35 degree slope with observed run-outs.
fs::path MakeEvent(const std::string& name, bool seven = false) {
  fs::path dir = FreshDir(name);
  Write(dir / "scene.toml", R"([terrain]
plane = { slope_deg = 35, slope_length_m = 20, runout_m = 10, width_m = 12, cell_m = 1 }
default_ground = "medium_soft"
[rock]
shape = { box = [0.4, 0.4, 0.3] }
[release]
runs = "runs.csv"
rocks = 4
seed = 3
[solver]
max_time_s = 3
)");
  Write(dir / "runs.csv",
        "trajectory_id,x_m,y_m,height_m,vx_mps\nr1,3,0,1,1\nr2,3,2,1,2\nr3,4,-2,1,0\nr4,4,3,1,1\n" +
            std::string(seven ? "r5,3,-4,1,1\nr6,4,1,1,2\nr7,3,4,1,0\n" : ""));
  Write(dir / "observed.csv", "trajectory_id,observed_runout_m\nr1,17\nr2,19\nr3,14\nr4,16\n" +
                                  std::string(seven ? "r5,18\nr6,15\nr7,13\n" : ""));
  Write(dir / "event.toml", R"(scene = "scene.toml"
[[observations]]
kind = "runout"
file = "observed.csv"
)");
  return dir;
}

const char* kGood = R"(event = "event.toml"
[[parameters]]
category = "medium_soft"
field = "mu_min"
lower = 0.1
upper = 0.9
[optimizer]
algorithm = "bobyqa"
max_evaluations = 6
[roughness]
steps = [1e-2]
seeds = 1
profile_points = 3
)";

// A small calibration completes, writes its four files and prints the summary. Budget: 6
// evaluations plus 1 + 1 + 1 for the roughness and 3 for the profile, of 16 rocks each. The
// roughness at a step of 1e-4, where it is sampling noise (the rocks-per-run rule applies).
TEST(CalibrateCommand, WritesTheGroundTableJsonAndHistory) {
  const fs::path dir = MakeEvent("good");
  std::string cal = kGood;
  const std::string step = "steps = [1e-2]";
  cal.replace(cal.find(step), step.size(), "steps = [1e-4]");
  Write(dir / "cal.toml", cal);
  std::string output;
  const int code =
      RunCommand(std::string(TALUS_BINARY) + " calibrate " + (dir / "cal.toml").string() +
                     " --out " + (dir / "out").string() + " --threads 2",
                 &output);
  ASSERT_EQ(code, 0) << output;
  EXPECT_NE(output.find("Calibration report"), std::string::npos) << output;
  for (const char* name :
       {"ground_table.toml", "ground_table.csv", "history.csv", "calibration.json",
        "convergence.svg", "observed_vs_simulated_runout.svg", "report.html"})
    EXPECT_TRUE(fs::exists(dir / "out" / name)) << name;
  // report.html: the fitted table, the plots inline (convergence, the profile, observed vs
  // simulated).
  const std::string report = Slurp(dir / "out" / "report.html");
  EXPECT_NE(report.find("<h2>Fitted parameters</h2>"), std::string::npos);
  EXPECT_NE(report.find("<th>medium_soft.mu_min</th>"), std::string::npos) << report;
  EXPECT_NE(report.find(">Profile of medium_soft.mu_min"), std::string::npos);
  EXPECT_NE(report.find(">run-out: observed vs simulated median</text>"), std::string::npos);
  // run.log: what was printed, evaluations included.
  const std::string log = Slurp(dir / "out" / "run.log");
  for (const char* line : {"command: ", " calibrate ", "\nCalibration ", "fit evaluation    0",
                           "Calibration report", "finished: exit 0"})
    EXPECT_NE(log.find(line), std::string::npos) << line << "\n" << log;
  // The plots: one dot per feasible evaluation and the best-so-far line; one dot per run before
  // and one after.
  const std::string convergence = Slurp(dir / "out" / "convergence.svg");
  const std::string scatter = Slurp(dir / "out" / "observed_vs_simulated_runout.svg");
  const auto count = [](const std::string& text, const std::string& what) {
    std::size_t n = 0;
    for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1))
      ++n;
    return n;
  };
  EXPECT_EQ(convergence.rfind("<svg ", 0), 0u);
  EXPECT_EQ(count(convergence, "<polyline"), 1u);
  EXPECT_EQ(count(scatter, "<circle"), 8u);  // 4 runs, before and after
  const auto json = nlohmann::json::parse(Slurp(dir / "out" / "calibration.json"));
  EXPECT_EQ(json["parameters"][0]["name"], "medium_soft.mu_min");
  EXPECT_LE(json["objective"]["after"].get<double>(), json["objective"]["before"].get<double>());
  EXPECT_LE(json["evaluations"].get<int>(), 6);
  EXPECT_TRUE(json["roughness"].is_object());
  EXPECT_TRUE(json["parameters"][0]["identified"].is_boolean());
  // The rocks-per-run rule with the file's 4 rocks per run: R (threshold / range)^2, the level
  // being sampling noise at a step of 1e-4 (and the seed's spread above 0).
  EXPECT_EQ(json["roughness"]["level_is_sampling_noise"], true);
  ASSERT_GT(json["roughness"]["level"].get<double>(), 0);
  const auto& profile = json["parameters"][0]["profile"];
  const double range = profile["range"], threshold = profile["threshold"];
  ASSERT_GT(range, 0);
  ASSERT_TRUE(profile["rocks_to_identify"].is_number()) << profile;
  EXPECT_NEAR(profile["rocks_to_identify"].get<double>(),
              4 * (threshold / range) * (threshold / range), 1e-12 * 4);
  // A range within what noise alone spans is never taken for identification.
  EXPECT_FALSE(profile["within_noise"].get<bool>() &&
               json["parameters"][0]["identified"].get<bool>());
  // Every evaluation ran the tight contact solve, whatever the simulations' default.
  EXPECT_EQ(json["solver"]["tolerance_m_s"].get<double>(), 1e-7);
  EXPECT_EQ(json["solver"]["tolerance_source"], "default");
  EXPECT_NE(output.find("Contact solve: tolerance 1e-07 m/s (default)\n"), std::string::npos)
      << output;
  const std::string csv = Slurp(dir / "out" / "ground_table.csv");
  EXPECT_EQ(csv.rfind("category,code,mu_min,mu_max,beta,kappa,nu\nmedium_soft,3,", 0), 0u) << csv;
  // One header line and one line per evaluation.
  const std::string history = Slurp(dir / "out" / "history.csv");
  EXPECT_EQ(std::count(history.begin(), history.end(), '\n'), json["evaluations"].get<int>() + 1);
  // The fitted table is a [ground.<name>] block a scene takes as it is.
  const std::string toml = Slurp(dir / "out" / "ground_table.toml");
  EXPECT_NE(toml.find("[ground.medium_soft]\ncode = 3\nmu_min = "), std::string::npos) << toml;
  std::string scene = Slurp(dir / "scene.toml") + toml;
  Write(dir / "fitted_scene.toml", scene);
  EXPECT_EQ(
      RunCommand(std::string(TALUS_BINARY) + " simulate " + (dir / "fitted_scene.toml").string() +
                     " --out " + (dir / "sim").string() + " --rocks 2",
                 &output),
      0)
      << output;
}

// The rocks-per-run rule needs the level to be sampling noise: with no other seeds and the
// roughness at a step of 1e-2 alone, talus does not give it and says why (docs/calibration.md,
// "How many rocks per run").
TEST(CalibrateCommand, TheRocksPerRunRuleIsNotGivenAgainstTheRoughnessAtALargeStep) {
  const fs::path dir = MakeEvent("large_step");
  std::string cal = kGood;
  cal.replace(cal.find("max_evaluations = 6"), 19, "max_evaluations = 2");
  cal.replace(cal.find("seeds = 1"), 9, "seeds = 0");
  cal += "[uncertainty]\nenabled = false\n";
  Write(dir / "cal.toml", cal);
  std::string output;
  ASSERT_EQ(RunCommand(std::string(TALUS_BINARY) + " calibrate " + (dir / "cal.toml").string() +
                           " --out " + (dir / "out").string() + " --threads 2",
                       &output),
            0)
      << output;
  EXPECT_NE(output.find("  rocks per run to identify: not estimated: at the roughness' smallest "
                        "step, 0.01, the objective's smooth change is part of it"),
            std::string::npos)
      << output;
  EXPECT_EQ(output.find("rocks per run on)"), std::string::npos) << output;
  EXPECT_EQ(output.find("rocks per run would"), std::string::npos) << output;
  const auto json = nlohmann::json::parse(Slurp(dir / "out" / "calibration.json"));
  EXPECT_EQ(json["roughness"]["level_is_sampling_noise"], false);
  EXPECT_TRUE(json["roughness"]["seed_values"].empty());
  EXPECT_TRUE(json["parameters"][0]["profile"]["rocks_to_identify"].is_null());
}

// On a terminal (script(1) gives the program one) the phases show their progress as one status
// line: the optimisation's last evaluation, or the phase and the rocks of its current evaluation;
// --quiet silences it with the information (warnings stay).
TEST(CalibrateCommand, PhasesShowProgressOnATerminalAndQuietSilencesIt) {
  if (std::system("command -v script >/dev/null 2>&1") != 0) GTEST_SKIP() << "no script(1)";
  const fs::path dir = MakeEvent("progress");
  std::string cal = kGood;
  cal.replace(cal.find("max_evaluations = 6"), 19, "max_evaluations = 2");
  cal += "[uncertainty]\nenabled = false\n";
  Write(dir / "cal.toml", cal);
  const auto on_a_terminal = [&](const std::string& out, const std::string& more) {
    std::string output;
    EXPECT_EQ(RunCommand("script -qec '" + std::string(TALUS_BINARY) + " calibrate " +
                             (dir / "cal.toml").string() + " --threads 2 --out " +
                             (dir / out).string() + more + "' /dev/null",
                         &output),
              0)
        << output;
    return output;
  };
  const std::string talkative = on_a_terminal("out", "");
  EXPECT_NE(talkative.find("\r  fit evaluation    1"), std::string::npos) << talkative;
  EXPECT_NE(talkative.find("\r  Measuring the roughness and the profiles at the optimum: "
                           "evaluation 1  [rocks "),
            std::string::npos)
      << talkative;
  const std::string quiet = on_a_terminal("quiet", " --quiet");
  EXPECT_EQ(quiet.find("evaluation"), std::string::npos) << quiet;
  EXPECT_EQ(quiet.find("Calibration"), std::string::npos) << quiet;
  std::istringstream lines(quiet);
  for (std::string line; std::getline(lines, line);)
    EXPECT_EQ(line.rfind("talus calibrate: WARNING: ", 0), 0u) << line;
}

// Each mistake is refused with exit code 2, naming the file, line and key, before any rock runs
// (no output directory is created).
// The six single impacts of Chant Sura: their scar depths are scored beside the energy ratios
// (the first contact episode's deepest penetration), and nothing is left unscored.
TEST(CalibrateCommand, SingleImpactScarDepthsAreScoredByCalibration) {
  const fs::path dir = talus::app::testing::FreshDir("talus_calibrate_tests", "not_scored");
  Write(dir / "cal.toml", "event = \"" + std::string(TALUS_SOURCE_DIR) +
                              "/cases/chant_sura/event_impacts.toml\"\nrocks = 4\n"
                              R"([[parameters]]
category = "medium_hard"
field = "mu_min"
lower = 0.1
upper = 1.5
[optimizer]
max_evaluations = 3
[roughness]
enabled = false
[uncertainty]
enabled = false
)");
  std::string output;
  ASSERT_EQ(RunCommand(std::string(TALUS_BINARY) + " calibrate " + (dir / "cal.toml").string() +
                           " --out " + (dir / "out").string() + " --threads 2",
                       &output),
            0)
      << output;
  const auto json = nlohmann::json::parse(Slurp(dir / "out" / "calibration.json"));
  EXPECT_TRUE(json["not_scored"].empty()) << json["not_scored"];
  EXPECT_EQ(output.find("Not scored: "), std::string::npos) << output;
  EXPECT_NE(output.find("12 observations of 6 runs"), std::string::npos) << output;
}

TEST(CalibrateCommand, BadFilesAreRefusedBeforeAnyRun) {
  const fs::path dir = MakeEvent("bad");
  const std::string cal = (dir / "cal.toml").string();
  const struct {
    std::string from, to, expected;
  } cases[] = {
      {"[optimizer]", "[optimiser]",
       cal + ":7: optimiser: unknown key (did you mean 'optimizer'?)"},
      {"field = \"mu_min\"", "field = \"mu_mn\"",
       cal + ":4: parameters[0].field: unknown parameter 'mu_mn' (did you mean 'mu_min'?); "
             "known: mu_min, mu_max, beta, kappa, nu, soil_strength, compaction_drag"},
      {"upper = 0.9", "upper = 0.1",
       cal + ":6: parameters[0].upper: medium_soft.mu_min: upper = 0.1 must be > lower = 0.1 (the "
             "bounds are empty)"},
      {"category = \"medium_soft\"", "category = \"medium_sft\"",
       cal + ":3: parameters[0].category: unknown ground category 'medium_sft' (did you mean "
             "'medium_soft'?); the scene has extra_soft, soft, medium_soft, medium, medium_hard, "
             "hard, extra_hard, snow"},
      {"algorithm = \"bobyqa\"", "algorithm = \"bobyqua\"",
       cal + ":8: optimizer.algorithm: unknown algorithm 'bobyqua' (did you mean 'bobyqa'?); "
             "known: bobyqa, sbplx, crs2_lm, direct_l, isres, ceres"},
      {"[optimizer]", "[objective]\nweights = { scar_length = 1 }\n[optimizer]",
       cal + ":8: objective.weights.scar_length: no observation of this kind; the event "
             "observes runout"},
      {"upper = 0.9",
       "upper = 0.9\n[[parameters]]\ncategory = \"medium_soft\"\nfield = "
       "\"mu_max\"\nlower = 0.01\nupper = 0.05",
       cal + ":2: parameters: medium_soft: mu_min >= 0.1 and mu_max <= 0.05 within the bounds: no "
             "parameter vector has mu_min <= mu_max"},
      {"profile_points = 3", "profile_points = 3\n[uncertainty]\nbootstrap = -1",
       cal + ":15: uncertainty.bootstrap: -1 must be 0 (off) or in 10 .. 100000 (resamples, each "
             "a refit of the parameters)"},
      {"profile_points = 3", "profile_points = 3\n[uncertainty]\nbootstrap = 1000000",
       cal + ":15: uncertainty.bootstrap: 1000000 must be 0 (off) or in 10 .. 100000 (resamples, "
             "each a refit of the parameters)"},
      {"profile_points = 3", "profile_points = 3\n[uncertainty]\nbootstrap_level = 95",
       cal + ":15: uncertainty.bootstrap_level: 95 must be in (0, 1)"},
      {"profile_points = 3", "profile_points = 3\n[uncertainty]\nenabled = false\nbootstrap = 20",
       cal + ":16: uncertainty.bootstrap: needs enabled = true (it is estimated with the "
             "covariance)"},
      {"profile_points = 3", "profile_points = 3\n[uncertainty]\nbootstrap = 10\nseeds = 1",
       cal + ":16: uncertainty.seeds: 1 must be 0 (off) or in 2 .. 1000 (refits with other "
             "release seeds; an sd needs 2)"},
      {"[optimizer]", "[solver]\ntolerance_m_s = 0\n[optimizer]",
       cal + ":8: solver.tolerance_m_s: 0 must be in (0, 1) m/s (the contact solve's tolerance "
             "of every evaluation)"},
      {"profile_points = 3", "profile_points = 3\n[uncertainty]\nseeds = 3",
       cal + ":15: uncertainty.seeds: needs bootstrap (its standard error is combined with the "
             "bootstrap's)"},
  };
  for (const auto& c : cases) {
    std::string text = kGood;
    text.replace(text.find(c.from), c.from.size(), c.to);
    Write(cal, text);
    std::string output;
    const int code = RunCommand(
        std::string(TALUS_BINARY) + " calibrate " + cal + " --out " + (dir / "out").string(),
        &output);
    EXPECT_EQ(code, 2) << output;
    EXPECT_EQ(output, "talus calibrate: " + c.expected + "\n");
    EXPECT_FALSE(fs::exists(dir / "out"));
  }
}

std::string Calibrate(const fs::path& dir, const std::string& options, std::string* output) {
  return std::to_string(RunCommand(std::string(TALUS_BINARY) + " calibrate " +
                                       (dir / "cal.toml").string() + " --out " +
                                       (dir / "out").string() + " --threads 2 " + options,
                                   output));
}

// Shape and ground fitted together: a rock block's roughness beside the ground's mu_min, a held-out
// run. shape_table.toml holds the block's fitted roughness as a [blocks.<id>] table and is used
// with the ground table (a scene with both simulates); calibration.json says which parameter is
// ground and which shape, and gives the bias per block of the fitted and the held-out runs.
TEST(CalibrateCommand, ShapeAndGroundFittedTogetherAreWrittenApart) {
  fs::path dir = FreshDir("shape");
  const std::string blocks = R"([blocks]
shape = "rock"
[blocks.round]
size_m = [0.4, 0.4, 0.3]
[blocks.slab]
size_m = [0.5, 0.4, 0.2]
shape = "box"
)";
  const std::string scene = R"([terrain]
plane = { slope_deg = 35, slope_length_m = 20, runout_m = 10, width_m = 12, cell_m = 1 }
default_ground = "medium_soft"
[release]
runs = "runs.csv"
rocks = 4
[solver]
max_time_s = 3
)";
  Write(dir / "scene.toml", scene + blocks);
  Write(dir / "runs.csv",
        "trajectory_id,x_m,y_m,height_m,block_id\nr1,3,0,1,round\nr2,3,2,1,slab\nr3,4,-2,1,round\n"
        "r4,4,3,1,slab\nr5,3,-4,1,round\n");
  Write(dir / "observed.csv",
        "trajectory_id,observed_runout_m\nr1,17\nr2,19\nr3,14\nr4,16\nr5,18\n");
  Write(dir / "event.toml",
        "scene = \"scene.toml\"\n[[observations]]\nkind = \"runout\"\n"
        "file = \"observed.csv\"\n");
  Write(dir / "cal.toml", R"(event = "event.toml"
[[parameters]]
category = "medium_soft"
field = "mu_min"
lower = 0.1
upper = 0.9
[[parameters]]
block = "round"
field = "roughness"
lower = 0
upper = 0.4
[optimizer]
max_evaluations = 6
[roughness]
enabled = false
[uncertainty]
enabled = false
)");
  std::string output;
  ASSERT_EQ(Calibrate(dir, "--holdout r5", &output), "0") << output;
  const auto json = nlohmann::json::parse(Slurp(dir / "out" / "calibration.json"));
  EXPECT_EQ(json["parameters"][0]["part"], "ground");
  EXPECT_EQ(json["parameters"][1]["name"], "blocks.round.roughness");
  EXPECT_EQ(json["parameters"][1]["part"], "shape");
  EXPECT_EQ(json["parameters"][1]["unit"], "1");
  ASSERT_EQ(json["fitted_runs_blocks"].size(), 2u);  // round (r1, r3) and slab (r2, r4)
  EXPECT_EQ(json["fitted_runs_blocks"][0]["block"], "round");
  EXPECT_EQ(json["fitted_runs_blocks"][0]["scored"], 2);
  ASSERT_EQ(json["holdout"]["blocks"].size(), 1u);  // r5, a round one
  EXPECT_EQ(json["holdout"]["blocks"][0]["block"], "round");
  const std::string ground = Slurp(dir / "out" / "ground_table.toml");
  EXPECT_EQ(ground.find("roughness"), std::string::npos) << ground;
  const std::string shapes = Slurp(dir / "out" / "shape_table.toml");
  const double roughness = json["parameters"][1]["final"].get<double>();
  EXPECT_NE(shapes.find("\n[blocks.round]\nshape = \"rock\"\nsize_m = [0.4, 0.4, 0.3]\n"),
            std::string::npos)
      << shapes;
  EXPECT_NE(shapes.find("\nroughness = "), std::string::npos) << shapes;
  EXPECT_EQ(shapes.find("[blocks.slab]"), std::string::npos) << shapes;
  EXPECT_NE(ground.find("Fitted jointly with block shapes"), std::string::npos) << ground;
  // The fitted scene: the ground table, the other block as it was, and the fitted block's whole
  // table as written.
  Write(dir / "fitted_scene.toml", scene + ground + R"([blocks]
[blocks.slab]
size_m = [0.5, 0.4, 0.2]
shape = "box"
)" + shapes.substr(shapes.find("[blocks.round]")));
  ASSERT_EQ(
      RunCommand(std::string(TALUS_BINARY) + " simulate " + (dir / "fitted_scene.toml").string() +
                     " --out " + (dir / "sim").string() + " --rocks 2",
                 &output),
      0)
      << output;
  const auto summary = nlohmann::json::parse(Slurp(dir / "sim" / "summary.json"));
  EXPECT_EQ(summary["blocks"][0]["id"], "round");  // blocks in key order
  EXPECT_EQ(summary["blocks"][0]["roughness"].get<double>(), roughness);
}

// Ceres with one run held out (--holdout r2) and 2-fold cross-validation of the other six: the
// held-out run is scored with the fitted and the reference (Table 1) parameters, each fold's runs
// by the fit without them, the folds split the six runs, and the covariance is reported.
TEST(CalibrateCommand, CeresWithAHeldOutRunAndCrossValidation) {
  const fs::path dir = MakeEvent("ceres", true);
  std::string cal = kGood;
  cal.replace(cal.find("bobyqa"), 6, "ceres");
  cal.replace(cal.find("max_evaluations = 6"), 19, "max_evaluations = 6\nfd_step = 0.05");
  Write(dir / "cal.toml", cal);
  std::string output;
  ASSERT_EQ(Calibrate(dir, "--holdout r2 --folds 2", &output), "0") << output;
  const auto json = nlohmann::json::parse(Slurp(dir / "out" / "calibration.json"));
  EXPECT_EQ(json["algorithm"], "ceres");
  EXPECT_EQ(json["runs"], 6);
  EXPECT_EQ(json["holdout"]["runs"], nlohmann::json::array({"r2"}));
  ASSERT_EQ(json["holdout"]["kinds"].size(), 1u);
  EXPECT_EQ(json["holdout"]["kinds"][0]["kind"], "runout");
  EXPECT_EQ(json["holdout"]["kinds"][0]["scored"], 1);
  EXPECT_TRUE(json["holdout"]["kinds"][0]["crps_fitted"].is_number());
  EXPECT_TRUE(json["holdout"]["kinds"][0]["crps_reference"].is_number());
  const auto& folds = json["cross_validation"]["folds"];
  ASSERT_EQ(folds.size(), 2u);
  std::vector<std::string> runs;
  for (const auto& fold : folds) {
    EXPECT_EQ(fold["runs"].size(), 3u);
    for (const auto& r : fold["runs"]) runs.push_back(r.get<std::string>());
  }
  std::sort(runs.begin(), runs.end());
  EXPECT_EQ(runs, (std::vector<std::string>{"r1", "r3", "r4", "r5", "r6", "r7"}));
  EXPECT_EQ(json["cross_validation"]["kinds"][0]["scored"], 6);
  EXPECT_TRUE(json["uncertainty"].is_object());
  EXPECT_TRUE(json["uncertainty"]["note"].is_string());
  // The covariance has numbers between identified parameters and null elsewhere, never a 0 that
  // would read as certainty.
  const auto& uncertainty = json["uncertainty"];
  for (std::size_t i = 0; i < uncertainty["identified"].size(); ++i)
    for (std::size_t k = 0; k < uncertainty["identified"].size(); ++k)
      EXPECT_EQ(
          uncertainty["covariance"][i][k].is_null(),
          !(uncertainty["identified"][i].get<bool>() && uncertainty["identified"][k].get<bool>()))
          << uncertainty.dump(2);
  EXPECT_TRUE(json["uncertainty"]["bootstrap"].is_null());  // off by default
  EXPECT_TRUE(json["uncertainty"]["seeds"].is_null());      // off by default
  EXPECT_GT(json["finite_difference_step"].get<double>(), 0);
  // When a budget ended a fit (the main one or a fold's), the checkpoint stays for --resume.
  const auto budget = [](const nlohmann::json& t) {
    return t == "max_evaluations" || t == "max_time";
  };
  bool any_budget = budget(json["termination"]);
  for (const auto& fold : folds) any_budget = any_budget || budget(fold["termination"]);
  EXPECT_EQ(fs::exists(dir / "out" / "checkpoint.json"), any_budget);
  // Unknown held-out runs and a second run over a checkpoint are refused before any rock runs.
  EXPECT_EQ(Calibrate(dir, "--holdout r9", &output), "2") << output;
  EXPECT_NE(output.find("--holdout: 'r9' is not a run of the event's scene"), std::string::npos)
      << output;
}

// The checkpoint of an older talus (an FNV-1a checksum) in --out is bad input naming the file and
// saying what to do, with --resume or without, before any rock runs; the directory is left as it
// was.
TEST(CalibrateCommand, ResumingACheckpointOfAnOlderTalusIsRefusedSayingWhatToDo) {
  const fs::path dir = MakeEvent("older_checkpoint");
  Write(dir / "cal.toml", kGood);
  fs::create_directories(dir / "out");
  const std::string older = talus::testing::kOlderTalusCheckpoint;
  Write(dir / "out" / "checkpoint.json", older);
  std::string output;
  EXPECT_EQ(Calibrate(dir, "--resume", &output), "2") << output;
  EXPECT_NE(output.find("talus calibrate: " + (dir / "out" / "checkpoint.json").string() +
                        ": a checkpoint of an older talus (its checksum is FNV-1a"),
            std::string::npos)
      << output;
  EXPECT_NE(output.find("remove it and run talus calibrate without --resume to start afresh"),
            std::string::npos)
      << output;
  // Without --resume it is refused the same way, not offered for resuming.
  EXPECT_EQ(Calibrate(dir, "", &output), "2") << output;
  EXPECT_NE(output.find("checkpoint.json: a checkpoint of an older talus"), std::string::npos)
      << output;
  EXPECT_EQ(output.find("resume it with --resume"), std::string::npos) << output;
  std::vector<std::string> left;
  for (const auto& entry : fs::directory_iterator(dir / "out"))
    left.push_back(entry.path().filename().string());
  EXPECT_EQ(left, std::vector<std::string>{"checkpoint.json"});
  EXPECT_EQ(Slurp(dir / "out" / "checkpoint.json"), older);
}

// A calibration stopped by its budget (5 evaluations) and resumed from its checkpoint with a
// budget of 10 ends exactly where an uninterrupted run with 10 does: the same evaluations, bit
// for bit (history.csv without its wall times), the same fitted table, the same bootstrap and seed
// refits (their evaluations are not checkpointed but re-run, deterministically).
TEST(CalibrateCommand, ResumedCalibrationEqualsAnUninterruptedOne) {
  const auto without_times = [](const std::string& csv) {
    std::string out;
    std::stringstream in(csv);
    for (std::string line; std::getline(in, line);) {
      const std::size_t note = line.rfind(',');
      const std::size_t time = line.rfind(',', note - 1);
      out += line.substr(0, time) + "\n";
    }
    return out;
  };
  // Without the profiles, which find mu_min unidentified with these few rocks (the bootstrap then
  // refits nothing).
  std::string cal = std::string(kGood) + "[uncertainty]\nbootstrap = 10\nseeds = 2\n";
  cal.replace(cal.find("[roughness]"), 11, "[roughness]\nenabled = false");
  cal.replace(cal.find("max_evaluations = 6"), 19, "max_evaluations = 10\nxtol_abs = 0");
  const fs::path whole = MakeEvent("whole");
  Write(whole / "cal.toml", cal);
  std::string output;
  ASSERT_EQ(Calibrate(whole, "", &output), "0") << output;

  const fs::path parts = MakeEvent("parts");
  std::string first = cal;
  first.replace(first.find("max_evaluations = 10"), 20, "max_evaluations = 5");
  Write(parts / "cal.toml", first);
  ASSERT_EQ(Calibrate(parts, "", &output), "0") << output;
  ASSERT_TRUE(fs::exists(parts / "out" / "checkpoint.json")) << output;
  EXPECT_EQ(Calibrate(parts, "", &output), "2") << output;  // not without --resume
  EXPECT_NE(output.find("resume it with --resume"), std::string::npos) << output;
  Write(parts / "cal.toml", cal);
  ASSERT_EQ(Calibrate(parts, "--resume", &output), "0") << output;
  EXPECT_NE(output.find("5 from a checkpoint"), std::string::npos) << output;

  const auto a = nlohmann::json::parse(Slurp(whole / "out" / "calibration.json"));
  const auto b = nlohmann::json::parse(Slurp(parts / "out" / "calibration.json"));
  EXPECT_EQ(a["evaluations"], 10);
  EXPECT_EQ(a["parameters"], b["parameters"]);
  EXPECT_EQ(a["objective"], b["objective"]);
  EXPECT_EQ(a["evaluations"], b["evaluations"]);
  auto bootstrap = a["uncertainty"]["bootstrap"], resumed = b["uncertainty"]["bootstrap"];
  ASSERT_TRUE(bootstrap.is_object()) << a.dump(1);
  EXPECT_EQ(bootstrap["resamples"], 10);
  EXPECT_EQ(bootstrap["refits"].size(), 10u);
  EXPECT_TRUE(bootstrap["standard_error"][0].is_number()) << bootstrap.dump(1);
  bootstrap.erase("wall_time_s");
  resumed.erase("wall_time_s");
  EXPECT_EQ(bootstrap, resumed);
  auto seeds = a["uncertainty"]["seeds"], seeds_resumed = b["uncertainty"]["seeds"];
  ASSERT_TRUE(seeds.is_object()) << a.dump(1);
  EXPECT_EQ(seeds["refits"].size(), 2u);
  EXPECT_TRUE(seeds["combined_standard_error"][0].is_number()) << seeds.dump(1);
  EXPECT_TRUE(a["parameters"][0]["combined_interval"][0].is_number()) << a.dump(1);
  seeds.erase("wall_time_s");
  seeds_resumed.erase("wall_time_s");
  EXPECT_EQ(seeds, seeds_resumed);
  EXPECT_EQ(Slurp(whole / "out" / "ground_table.csv"), Slurp(parts / "out" / "ground_table.csv"));
  EXPECT_EQ(without_times(Slurp(whole / "out" / "history.csv")),
            without_times(Slurp(parts / "out" / "history.csv")));
}

// SIGINT in the middle of a fit: exit code 130, no output but the checkpoint, which holds every
// evaluation the run printed (it is written at least on the way out, not only every few seconds),
// and --resume goes on from all of them to a complete result.
TEST(CalibrateCommand, SigintKeepsEveryEvaluationForResume) {
  const fs::path dir = MakeEvent("sigint", true);
  std::string cal = kGood;
  cal.replace(cal.find("max_evaluations = 6"), 19, "max_evaluations = 12\nxtol_abs = 0");
  cal.insert(cal.find("[[parameters]]"), "rocks = 24\n");  // slow enough to be interrupted
  Write(dir / "cal.toml", cal);
  const fs::path out = dir / "out";
  const fs::path log = dir / "log.txt";
  const pid_t pid = talus::app::testing::StartProgram(
      TALUS_BINARY, {"calibrate", (dir / "cal.toml").string(), "--out", out.string()}, log);
  ASSERT_GT(pid, 0);
  const auto printed = [&] {
    const std::string text = Slurp(log);
    int n = 0;
    for (std::size_t at = text.find("fit evaluation"); at != std::string::npos;
         at = text.find("fit evaluation", at + 1))
      ++n;
    return n;
  };
  const auto deadline = std::chrono::steady_clock::now() +
                        std::chrono::duration<double>(talus::app::testing::kHangSeconds);
  while (printed() < 3 && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  ::kill(pid, SIGINT);
  const int status = talus::app::testing::WaitFor(pid, talus::app::testing::kHangSeconds);
  const std::string text = Slurp(log);
  ASSERT_EQ(status, 130) << text;
  const int before = printed();
  ASSERT_GE(before, 3) << text;
  ASSERT_LT(before, 12) << "the fit ended before the signal\n" << text;
  const auto checkpoint = nlohmann::json::parse(Slurp(out / "checkpoint.json"));
  EXPECT_GE(static_cast<int>(checkpoint["stages"]["fit"].size()), before);
  EXPECT_FALSE(fs::exists(out / "calibration.json"));

  std::string output;
  ASSERT_EQ(Calibrate(dir, "--resume", &output), "0") << output;
  EXPECT_NE(output.find(std::to_string(checkpoint["stages"]["fit"].size()) + " from a checkpoint"),
            std::string::npos)
      << output;
  EXPECT_EQ(nlohmann::json::parse(Slurp(out / "calibration.json"))["evaluations"], 12);
}

#ifdef TALUS_MPIEXEC

std::string MpiRun(const std::string& ranks) {
  return "timeout -s KILL 120 " + std::string(TALUS_MPIEXEC) +
         " --oversubscribe --allow-run-as-root " + ranks;
}

// calibration.json without what depends on the machine and the processes (timings, threads).
nlohmann::json WithoutTimings(nlohmann::json j) {
  if (j.is_object()) {
    nlohmann::json out = nlohmann::json::object();
    for (auto& [key, value] : j.items())
      if (key.find("wall_time") == std::string::npos && key != "timings" && key != "threads")
        out[key] = WithoutTimings(value);
    return out;
  }
  if (j.is_array()) {
    nlohmann::json out = nlohmann::json::array();
    for (auto& value : j) out.push_back(WithoutTimings(value));
    return out;
  }
  return j;
}

// Runs CALIBRATION (the calibration file's text) in one process into dir/one and with mpirun -n 2
// into dir/two, both on one thread per process; returns the two-rank run's output.
std::string RunInOneProcessAndOnTwoRanks(const fs::path& dir, const std::string& calibration) {
  Write(dir / "cal.toml", calibration);
  std::string output;
  const std::string args = " calibrate " + (dir / "cal.toml").string() + " --threads 1 --out ";
  EXPECT_EQ(RunCommand(TALUS_BINARY + args + (dir / "one").string(), &output), 0) << output;
  EXPECT_EQ(RunCommand(MpiRun("-n 2 ") + TALUS_BINARY + args + (dir / "two").string(), &output), 0)
      << output;
  EXPECT_NE(output.find("2 MPI ranks"), std::string::npos) << output;
  return output;
}

// mpirun -n 2 talus calibrate: each evaluation's rocks divided between the ranks give the
// one-process calibration: the same evaluations, optimum, profiles and files (timings aside).
TEST(CalibrateMpi, TwoRanksGiveTheOneProcessCalibration) {
  const fs::path dir = MakeEvent("mpi");
  const std::string output = RunInOneProcessAndOnTwoRanks(dir, kGood);
  ASSERT_FALSE(HasFailure());
  // Rank 0 alone tells the story.
  std::size_t reports = 0;
  for (std::size_t at = output.find("Calibration report"); at != std::string::npos;
       at = output.find("Calibration report", at + 1))
    ++reports;
  EXPECT_EQ(reports, 1u) << output;
  for (const char* name : {"ground_table.toml", "ground_table.csv", "convergence.svg",
                           "observed_vs_simulated_runout.svg"})
    EXPECT_EQ(Slurp(dir / "one" / name), Slurp(dir / "two" / name)) << name;
  const auto one = nlohmann::json::parse(Slurp(dir / "one" / "calibration.json"));
  const auto two = nlohmann::json::parse(Slurp(dir / "two" / "calibration.json"));
  EXPECT_EQ(WithoutTimings(one), WithoutTimings(two));
}

// The bootstrap over runs and the refits with other release seeds under mpirun -n 2: every refit's
// evaluations are divided between the ranks as the fit's are, so the intervals, standard errors and
// the combined uncertainty equal the one-process calibration's.
TEST(CalibrateMpi, TwoRanksGiveTheOneProcessBootstrapAndSeedRefits) {
  const fs::path dir = MakeEvent("mpi_uncertainty");
  RunInOneProcessAndOnTwoRanks(dir,
                               std::string(kGood) + "[uncertainty]\nbootstrap = 10\nseeds = 2\n");
  ASSERT_FALSE(HasFailure());
  const auto one = nlohmann::json::parse(Slurp(dir / "one" / "calibration.json"));
  const auto two = nlohmann::json::parse(Slurp(dir / "two" / "calibration.json"));
  ASSERT_TRUE(one["uncertainty"]["bootstrap"].is_object()) << one.dump(2);
  ASSERT_TRUE(one["uncertainty"]["seeds"].is_object()) << one.dump(2);
  EXPECT_EQ(WithoutTimings(one), WithoutTimings(two));
}

// A rank that cannot load the calibration ends every rank with one message, before any rock runs;
// ranks started with different calibrations are refused.
TEST(CalibrateMpi, ARankThatFailsOrDiffersEndsTheRunWithOneMessage) {
  const fs::path dir = MakeEvent("mpi_bad");
  Write(dir / "cal.toml", kGood);
  std::string other = kGood;
  other.replace(other.find("max_evaluations = 6"), 19, "max_evaluations = 5");
  Write(dir / "other.toml", other);
  const std::string out = " --out " + (dir / "out").string();
  std::string output;
  EXPECT_EQ(RunCommand(MpiRun("-n 1 ") + TALUS_BINARY + " calibrate " +
                           (dir / "cal.toml").string() + out + " : -n 1 " + TALUS_BINARY +
                           " calibrate " + (dir / "missing.toml").string() + out,
                       &output),
            2)
      << output;
  EXPECT_NE(output.find("talus calibrate: rank 1: "), std::string::npos) << output;
  EXPECT_NE(output.find("missing.toml"), std::string::npos) << output;
  EXPECT_FALSE(fs::exists(dir / "out"));
  EXPECT_EQ(RunCommand(MpiRun("-n 1 ") + TALUS_BINARY + " calibrate " +
                           (dir / "cal.toml").string() + out + " : -n 1 " + TALUS_BINARY +
                           " calibrate " + (dir / "other.toml").string() + out,
                       &output),
            2)
      << output;
  EXPECT_NE(output.find("rank 1: started with another calibration than rank 0"), std::string::npos)
      << output;
  EXPECT_FALSE(fs::exists(dir / "out" / "calibration.json"));
}

#endif

}  // namespace
