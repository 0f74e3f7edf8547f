// What the program prints and keeps (app/console.hpp): --quiet silences information, never
// warnings or errors; run.log holds the version, the command line, everything said and the wall
// time, and is written only for a run that succeeded.

#include "app/console.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "tests/test_tmp.hpp"

namespace talus::app {
namespace {

namespace fs = std::filesystem;

TEST(Console, QuietSilencesInformationButNotWarningsAndKeepsBoth) {
  const char* argv[] = {"talus", "validate", "my event.toml", "--quiet"};
  SetCommandLine(4, argv);
  SetQuiet(true);
  ::testing::internal::CaptureStdout();
  ::testing::internal::CaptureStderr();
  Say("Event %s: %d observations\n", "e.toml", 10);
  Warn("validate", "10 of 18 rocks were still moving at max_time");
  Fail("validate", "cannot write out/scores.json");
  const std::string out = ::testing::internal::GetCapturedStdout();
  const std::string err = ::testing::internal::GetCapturedStderr();
  SetQuiet(false);
  EXPECT_EQ(out, "");
  EXPECT_EQ(err,
            "talus validate: WARNING: 10 of 18 rocks were still moving at max_time\n"
            "talus validate: cannot write out/scores.json\n");
  const std::string log = RunLogText(0);
  EXPECT_EQ(log.rfind("talus ", 0), 0u);
  EXPECT_NE(log.find("command: talus validate 'my event.toml' --quiet\n"), std::string::npos)
      << log;
  EXPECT_NE(log.find("\nstarted: 20"), std::string::npos);
  EXPECT_NE(log.find("Event e.toml: 10 observations\n"), std::string::npos);
  EXPECT_NE(log.find("talus validate: WARNING: 10 of 18 rocks"), std::string::npos);
  EXPECT_NE(log.find("finished: exit 0 after "), std::string::npos);
}

TEST(Console, InformationGoesToStdoutWithoutQuietAndNoProgressOffATerminal) {
  SetQuiet(false);
  ::testing::internal::CaptureStdout();
  ::testing::internal::CaptureStderr();
  Say("Wrote %d files\n", 3);
  Status("[####] 3/4 rocks");  // stderr is no terminal here: nothing
  EndStatus();
  EXPECT_EQ(::testing::internal::GetCapturedStdout(), "Wrote 3 files\n");
  EXPECT_EQ(::testing::internal::GetCapturedStderr(), "");
  EXPECT_FALSE(ShowsProgress());
  EXPECT_EQ(RunLogText(0).find("3/4 rocks"), std::string::npos);  // progress is not kept
}

// The progress line of simulate's and validate's rocks and of merge's phases: a bar of 30, the
// counts, the rate so far and the time left at that rate.
TEST(Console, ProgressLineShowsBarCountsRateAndTimeLeft) {
  EXPECT_EQ(ProgressLine("", 3, 10, "rocks", 0, 1.5),
            "[#########                     ] 3/10 rocks  2.0/s  4 s left");
  EXPECT_EQ(ProgressLine("Checking the parts", 1.5, 3.0, "MB", 1, 0.5),
            "Checking the parts [###############               ] 1.5/3.0 MB  3.0/s  1 s left");
  EXPECT_EQ(ProgressLine("Merging rocks.csv", 0, 4, "parts", 0, 0),
            "Merging rocks.csv [                              ] 0/4 parts  0.0/s  ? left");
  EXPECT_EQ(ProgressLine("", 12, 12, "rocks", 0, 2),
            "[##############################] 12/12 rocks  6.0/s  0 s left");
}

TEST(Console, RunLogIsWrittenIntoItsDirectoryOnlyWhenTheRunSucceeded) {
  const fs::path dir = talus::testing::TestTmpRoot() / "console_run_log";
  fs::remove_all(dir);
  fs::create_directories(dir);
  WriteRunLog(0);  // no directory set: nothing, anywhere
  SetRunLogDirectory(dir.string());
  WriteRunLog(1);  // a failed run leaves --out as it was
  EXPECT_FALSE(fs::exists(dir / "run.log"));
  WriteRunLog(0);
  std::ifstream in(dir / "run.log");
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_NE(text.str().find("finished: exit 0"), std::string::npos) << text.str();
  std::size_t files = 0;
  for ([[maybe_unused]] const auto& entry : fs::directory_iterator(dir)) ++files;
  EXPECT_EQ(files, 1u);  // no temporary file left
  SetRunLogDirectory("");
}

}  // namespace
}  // namespace talus::app
