// End to end through the talus program: `talus validate` on a tiny event.

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "run_talus.hpp"

namespace {

namespace fs = std::filesystem;

fs::path FreshDir(const std::string& name) {
  return talus::app::testing::FreshDir("talus_app_tests", name);
}

using talus::app::testing::RunCommand;

using talus::app::testing::Slurp;

using talus::app::testing::Write;

// The small event of run_talus.hpp in a fresh directory.
fs::path MakeEvent(const std::string& name, const std::string& event_extra = "") {
  fs::path dir = FreshDir(name);
  talus::app::testing::WriteSmallEvent(dir, event_extra);
  return dir;
}

TEST(ValidateCommand, WritesScoresThatDoNotDependOnTheThreadCount) {
  const fs::path dir = MakeEvent("validate");
  std::string output;
  for (int threads : {1, 2}) {
    const std::string out = (dir / ("out" + std::to_string(threads))).string();
    ASSERT_EQ(RunCommand(std::string(TALUS_BINARY) + " validate " + (dir / "event.toml").string() +
                             " --out " + out + " --threads " + std::to_string(threads),
                         &output),
              0)
        << output;
  }
  for (const char* file : {"scores.json", "observations.csv", "observed_vs_simulated.svg",
                           "pit.svg", "deposits.png", "report.html"})
    EXPECT_TRUE(fs::exists(dir / "out1" / file)) << file;
  // report.html: the same for any thread count (no timings), with the scores and the warnings.
  const std::string report = Slurp(dir / "out1" / "report.html");
  EXPECT_EQ(report, Slurp(dir / "out2" / "report.html"));
  EXPECT_NE(report.find("<th>run-out (m)</th><td>3</td><td>3</td><td>CRPS</td>"),
            std::string::npos);
  // 4 s is too short for some of the rocks: their run-outs are censored, and validate says so on
  // the console, in scores.json and first in report.html.
  EXPECT_NE(output.find("talus validate: WARNING: "), std::string::npos) << output;
  EXPECT_NE(output.find("still moving at max_time_s = 4 s"), std::string::npos) << output;
  EXPECT_NE(report.find("still moving at max_time_s = 4 s"), std::string::npos);
  EXPECT_LT(report.find("<h2>Warnings</h2>"), report.find("Scores per kind"));
  EXPECT_EQ(Slurp(dir / "out1" / "observations.csv"), Slurp(dir / "out2" / "observations.csv"));
  const auto scores = nlohmann::json::parse(Slurp(dir / "out1" / "scores.json"));
  ASSERT_EQ(scores["warnings"].size(), 1u) << scores["warnings"];
  EXPECT_NE(scores["warnings"][0].get<std::string>().find("max_time"), std::string::npos);
  EXPECT_EQ(scores["runs"], 3);
  EXPECT_EQ(scores["rocks_per_run"], 6);
  EXPECT_EQ(scores["observations"], 3 + 3 + 2 * 2);  // runouts, deposits, 2 per impact
  EXPECT_EQ(scores["kinds"]["runout"]["observations"], 3);
  EXPECT_EQ(scores["kinds"]["runout"]["scored"], 3);
  EXPECT_EQ(scores["kinds"]["deposit"]["score"], "energy_score");
  EXPECT_EQ(scores["kinds"]["impact_energy_ratio"]["scored"], 2);  // episodes were recorded
  EXPECT_TRUE(scores["kinds"]["runout"]["mean_score"].is_number());
  EXPECT_EQ(scores["kinds"]["runout"]["skill_vs_reference"], 0.0);  // Table 1 is the scene's
  EXPECT_NE(output.find("runout (m)"), std::string::npos) << output;
}

// A file-size limit (`ulimit -f`, soft and hard) hit while writing the outputs: one error and
// exit 1 with no output and no temporary file left, as for a full disk. SIGXFSZ killed validate
// (exit 153), leaving its staging directory.
TEST(ValidateCommand, AFileSizeLimitIsOneErrorAndLeavesNothing) {
  const fs::path dir = MakeEvent("file_size_limit");
  const fs::path out = dir / "out";
  std::string output;
  EXPECT_EQ(RunCommand("ulimit -f 4; exec " + std::string(TALUS_BINARY) + " validate " +
                           (dir / "event.toml").string() + " --out " + out.string(),
                       &output),
            1)
      << output;
  EXPECT_NE(output.find("talus validate: cannot write"), std::string::npos) << output;
  EXPECT_TRUE(!fs::exists(out) || fs::is_empty(out)) << output;
}

// Under a terminal (script(1) gives the program one) validate shows the rocks' progress; --quiet
// silences it and the information, not the warning; run.log keeps what was said either way.
TEST(ValidateCommand, ProgressOnATerminalAndQuietKeepsOnlyWarningsButRunLogKeepsAll) {
  if (std::system("command -v script >/dev/null 2>&1") != 0) GTEST_SKIP() << "no script(1)";
  const fs::path dir = MakeEvent("quiet");
  const auto on_a_terminal = [&](const std::string& out, const std::string& more) {
    std::string output;
    EXPECT_EQ(RunCommand("script -qec '" + std::string(TALUS_BINARY) + " validate " +
                             (dir / "event.toml").string() + " --out " + (dir / out).string() +
                             more + "' /dev/null",
                         &output),
              0)
        << output;
    return output;
  };
  const std::string talkative = on_a_terminal("out", "");
  EXPECT_NE(talkative.find("\r[###"), std::string::npos) << talkative;  // the progress bar
  EXPECT_NE(talkative.find(" rocks "), std::string::npos);
  EXPECT_NE(talkative.find("Event "), std::string::npos);
  const std::string quiet = on_a_terminal("quiet", " --quiet");
  EXPECT_EQ(quiet.find("[#"), std::string::npos) << quiet;
  EXPECT_EQ(quiet.find("Event "), std::string::npos) << quiet;
  EXPECT_EQ(quiet.rfind("talus validate: WARNING: ", 0), 0u) << quiet;
  const std::string log = Slurp(dir / "quiet" / "run.log");
  for (const char* line : {"talus ", "command: ", " validate ", " --quiet\n", "\nEvent ",
                           "\nWrote 6 files to ", "talus validate: WARNING: ", "finished: exit 0"})
    EXPECT_NE(log.find(line), std::string::npos) << line << "\n" << log;
  EXPECT_EQ(log.find("[#"), std::string::npos);  // progress is not kept
}

TEST(ValidateCommand, BadEventsFailBeforeAnyRockNamingFileLineAndKey) {
  std::string output;
  const fs::path dir = MakeEvent("validate_bad",
                                 "[[observations]]\nkind = \"runouts\"\n"
                                 "file = \"observed.csv\"\n");
  EXPECT_EQ(RunCommand(std::string(TALUS_BINARY) + " validate " + (dir / "event.toml").string() +
                           " --out " + (dir / "out").string(),
                       &output),
            2);
  EXPECT_NE(output.find("event.toml:12: observations[3].kind: unknown kind 'runouts' (did you "
                        "mean 'runout'?)"),
            std::string::npos)
      << output;
  EXPECT_FALSE(fs::exists(dir / "out" / "scores.json"));
  EXPECT_FALSE(fs::exists(dir / "out" / "run.log"));  // only a run that succeeded leaves one
  // An observation of a run the scene does not have.
  const fs::path other = MakeEvent("validate_run");
  Write(other / "observed.csv", "trajectory_id,x_m,y_m,observed_runout_m\nr1,20,0,17\nr9,1,1,1\n");
  EXPECT_EQ(RunCommand(std::string(TALUS_BINARY) + " validate " + (other / "event.toml").string() +
                           " --out " + (other / "out").string(),
                       &output),
            2);
  EXPECT_NE(output.find("observed.csv:3: run 'r9' is not a run of the scene"), std::string::npos)
      << output;
}

}  // namespace

namespace {

// The Chant Sura single impacts end to end (cases/chant_sura/event_impacts.toml): six runs made
// from the table, their energy ratios scored, the scar depths reported as not scored; a table
// with an impact angle out of range fails before any rock with its file, line and column.
TEST(ValidateCommand, ChantSuraSingleImpactsAreScoredWithTheirScarDepths) {
  const fs::path dir = FreshDir("single_impacts");
  const fs::path event = fs::path(TALUS_SOURCE_DIR) / "cases/chant_sura/event_impacts.toml";
  std::string output;
  ASSERT_EQ(RunCommand(std::string(TALUS_BINARY) + " validate " + event.string() + " --out " +
                           (dir / "out").string() + " --rocks 8 --threads 2",
                       &output),
            0)
      << output;
  EXPECT_EQ(output.find("Not scored: "), std::string::npos) << output;
  // The runs stop at 0.6 s by design: a single impact is not censored by max_time, so no warning.
  EXPECT_EQ(output.find("max_time"), std::string::npos) << output;
  const auto scores = nlohmann::json::parse(Slurp(dir / "out" / "scores.json"));
  EXPECT_EQ(scores["runs"], 6);
  EXPECT_EQ(scores["observations"], 12);
  EXPECT_EQ(scores["kinds"]["impact_energy_ratio"]["scored"], 6);
  EXPECT_EQ(scores["kinds"]["impact_scar_depth"]["scored"], 6);
  EXPECT_TRUE(scores["not_scored"].empty());

  // The same event over a copy of the table with an impact angle of 95 degrees.
  const fs::path bad = FreshDir("single_impacts_bad");
  const fs::path cases = fs::path(TALUS_SOURCE_DIR) / "cases/chant_sura";
  for (const char* file : {"scene_impacts.toml", "event_impacts.toml"})
    fs::copy_file(cases / file, bad / file);
  std::string table = Slurp(cases / "impacts_esurf2019.csv");
  const std::size_t angle = table.find(",24.90702392018205,");
  ASSERT_NE(angle, std::string::npos);
  table.replace(angle, 19, ",95,");
  Write(bad / "impacts_esurf2019.csv", table);
  EXPECT_EQ(
      RunCommand(std::string(TALUS_BINARY) + " validate " + (bad / "event_impacts.toml").string() +
                     " --out " + (bad / "out").string(),
                 &output),
      2)
      << output;
  EXPECT_NE(output.find("impacts_esurf2019.csv:2: column 'impact_angle_deg': impact angle 95 deg "
                        "is outside (0, 90]"),
            std::string::npos)
      << output;
  EXPECT_FALSE(fs::exists(bad / "out" / "scores.json"));
}

}  // namespace
