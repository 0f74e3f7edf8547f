// The checks of command-line values the verbs share: the messages name the bound and the value.

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>

#include "app/commands.hpp"
#include "tests/test_tmp.hpp"

namespace talus::app {
namespace {

std::string Check(const CLI::Validator& validator, std::string text) { return validator(text); }

TEST(IntegerRange, AcceptsTheBoundsAndWhatLiesBetween) {
  const CLI::Validator v = IntegerRange(-3, 10);
  for (const char* ok : {"-3", "0", "7", "10"}) EXPECT_EQ(Check(v, ok), "") << ok;
}

TEST(IntegerRange, NamesTheViolatedBoundWithTheValueGiven) {
  const CLI::Validator v = IntegerRange(1, 10);
  EXPECT_EQ(Check(v, "0"), "must be >= 1, got 0");
  EXPECT_EQ(Check(v, "11"), "must be <= 10, got 11");
  // Beyond long long: the bound on that side, not a parse error.
  EXPECT_EQ(Check(v, "99999999999999999999"), "must be <= 10, got 99999999999999999999");
  EXPECT_EQ(Check(v, "-99999999999999999999"), "must be >= 1, got -99999999999999999999");
}

TEST(IntegerRange, RefusesWhatIsNotAWholeNumber) {
  const CLI::Validator v = IntegerRange(0, 100);
  EXPECT_EQ(Check(v, "abc"), "must be an integer, got 'abc'");
  EXPECT_EQ(Check(v, "5x"), "must be an integer, got '5x'");
  EXPECT_EQ(Check(v, "2.5"), "must be an integer, got '2.5'");
  EXPECT_EQ(Check(v, ""), "must be an integer, got ''");
}

TEST(ThreadCount, AllowsZeroToFourThreadsPerCoreAndSaysWhyNotMore) {
  const int cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  EXPECT_EQ(MaxThreads(), std::max(kMinMaxThreads, kThreadsPerCore * cores));
  EXPECT_GE(MaxThreads(), 16);
  const CLI::Validator v = ThreadCount();
  EXPECT_EQ(Check(v, "0"), "");
  EXPECT_EQ(Check(v, std::to_string(MaxThreads())), "");
  const std::string why = Check(v, std::to_string(MaxThreads() + 1));
  EXPECT_EQ(why.rfind("must be <= " + std::to_string(MaxThreads()), 0), 0u) << why;
  EXPECT_NE(why.find("this machine has " + std::to_string(cores) + " cores"), std::string::npos)
      << why;
  EXPECT_EQ(Check(v, "-1"), "must be >= 0, got -1");  // no machine note for that bound
}

std::filesystem::path Fresh(const std::string& name) {
  auto dir = talus::testing::TestTmpRoot() / "talus_app_checks" / name;
  std::filesystem::remove_all(dir);
  return dir;
}

TEST(PrepareOutputDirectory, CreatesTheDirectoryWithItsParents) {
  const auto dir = Fresh("nested") / "a" / "b";
  EXPECT_EQ(PrepareOutputDirectory(dir.string()), "");
  EXPECT_TRUE(std::filesystem::is_directory(dir));
  EXPECT_EQ(PrepareOutputDirectory(dir.string()), "");  // an existing directory is fine
}

TEST(PrepareOutputDirectory, RefusesAFileOrAPathThroughAFile) {
  const auto dir = Fresh("file");
  std::filesystem::create_directories(dir);
  const auto file = dir / "taken";
  std::ofstream(file) << "x";
  EXPECT_EQ(PrepareOutputDirectory(file.string()),
            "--out " + file.string() + " exists and is not a directory");
  const std::string why = PrepareOutputDirectory((file / "below").string());
  EXPECT_EQ(why.rfind("cannot create the output directory " + (file / "below").string() + ": ", 0),
            0u)
      << why;
}

}  // namespace
}  // namespace talus::app
