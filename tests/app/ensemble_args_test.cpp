// --rocks, --threads and --seed (app/ensemble_args.hpp), shared by talus simulate and validate:
// parsed by CLI11 with their checks, and applied to a release -- which stays as the scene gave
// it without them, and whose total rock count they may not push beyond its bound.

#include "app/ensemble_args.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "common/error.hpp"

namespace talus::app {
namespace {

// A release of two runs, 3 rocks each, seed 5.
ensemble::ReleaseSpec TwoRuns() {
  ensemble::ReleaseSpec r;
  for (const char* id : {"a", "b"}) {
    ensemble::ReleaseRun run;
    run.id = id;
    r.runs.push_back(run);
  }
  r.rocks_per_release = 3;
  r.seed = 5;
  return r;
}

// Parses `args` into an EnsembleArgs; "" or CLI11's message.
std::string Parse(std::vector<std::string> args, EnsembleArgs* out) {
  CLI::App app("test");
  AddEnsembleOptions(&app, out, "run");
  args.insert(args.begin(), "talus");
  std::vector<const char*> argv;
  for (const std::string& a : args) argv.push_back(a.c_str());
  try {
    app.parse(static_cast<int>(argv.size()), argv.data());
  } catch (const CLI::ParseError& e) {
    return e.what();
  }
  return "";
}

TEST(EnsembleArgs, WithoutOptionsTheReleaseIsTheScenes) {
  EnsembleArgs args;
  ASSERT_EQ(Parse({}, &args), "");
  EXPECT_EQ(args.rocks, 0);
  EXPECT_EQ(args.threads, 0);
  EXPECT_FALSE(args.seed.has_value());
  ensemble::ReleaseSpec r = TwoRuns();
  args.ApplyTo(r);
  EXPECT_EQ(r.rocks_per_release, 3);
  EXPECT_EQ(r.total_rocks(), 6);
  EXPECT_EQ(r.seed, 5u);
}

TEST(EnsembleArgs, RocksAndSeedOverrideTheScene) {
  EnsembleArgs args;
  ASSERT_EQ(Parse({"--rocks", "40", "--seed", "0", "--threads", "2"}, &args), "");
  EXPECT_EQ(args.threads, 2);
  ensemble::ReleaseSpec r = TwoRuns();
  args.ApplyTo(r);
  EXPECT_EQ(r.RocksOf(0), 40);
  EXPECT_EQ(r.RocksOf(1), 40);
  EXPECT_EQ(r.total_rocks(), 80);
  EXPECT_EQ(r.seed, 0u);  // 0 is a seed, not "none"
  // The largest seed a scene file can hold (int64) is accepted.
  ASSERT_EQ(Parse({"--seed", "9223372036854775807"}, &args), "");
  EXPECT_EQ(*args.seed, 9223372036854775807ull);
}

// The checks name the option, the bound and the value; the help names what a rock count is per.
TEST(EnsembleArgs, OutOfRangeValuesAreRefusedByTheParser) {
  EnsembleArgs args;
  EXPECT_NE(Parse({"--rocks", "0"}, &args).find("must be >= 1, got 0"), std::string::npos);
  EXPECT_NE(Parse({"--rocks", "-3"}, &args).find("--rocks"), std::string::npos);
  EXPECT_NE(Parse({"--seed", "-1"}, &args).find("must be >= 0, got -1"), std::string::npos);
  EXPECT_NE(Parse({"--seed", "9223372036854775808"}, &args).find("must be <= 9223372036854775807"),
            std::string::npos);
  EXPECT_NE(Parse({"--rocks", "many"}, &args).find("must be an integer, got 'many'"),
            std::string::npos);
  CLI::App app("test");
  AddEnsembleOptions(&app, &args, "release point");
  EXPECT_NE(app.help().find("Rocks per release point (overrides the scene)"), std::string::npos)
      << app.help();
}

// Too many rocks in all (2 runs x 6e8 > 1e9) is an InputError naming --rocks and its value.
TEST(EnsembleArgs, TooManyRocksInAllIsAnInputErrorNamingRocks) {
  EnsembleArgs args;
  args.rocks = 600'000'000;
  ensemble::ReleaseSpec r = TwoRuns();
  try {
    args.ApplyTo(r);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("--rocks 600000000: ", 0), 0u) << e.what();
  }
}

}  // namespace
}  // namespace talus::app
