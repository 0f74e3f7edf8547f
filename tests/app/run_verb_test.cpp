// The verbs' ladder: a run that succeeds commits its outputs; an interrupted or failed one leaves
// --out as it was, with the exit code and the one message the verbs give.

#include "app/run_verb.hpp"

#include <gtest/gtest.h>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "app/commands.hpp"
#include "common/error.hpp"

namespace talus::app {
namespace {

namespace fs = std::filesystem;

fs::path FreshDir(const std::string& name) {
  fs::path dir = fs::temp_directory_path() / ("talus_run_verb_test_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

std::vector<std::string> Entries(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(dir)) names.push_back(entry.path().filename());
  return names;
}

void Write(const std::string& path, const std::string& text) { std::ofstream(path) << text; }

TEST(RunStaged, ASuccessfulRunCommitsAndSaysNothing) {
  const fs::path out = FreshDir("ok");
  std::optional<StagingDirectory> staging;
  bool failed = false;
  VerbHooks hooks;
  hooks.on_failure = [&](bool) { failed = true; };
  const VerbOutcome outcome = RunStaged(
      out.string(), staging,
      [&] {
        staging.emplace(out.string());
        Write(staging->path("a.txt"), "a");
        staging->Commit({"a.txt"});
      },
      hooks);
  EXPECT_EQ(outcome.code, kExitOk);
  EXPECT_EQ(outcome.message, "");
  EXPECT_FALSE(failed);
  EXPECT_EQ(Entries(out), std::vector<std::string>{"a.txt"});
}

TEST(RunStaged, AnInterruptedRunRemovesItsFilesAndExitsWith128PlusTheSignal) {
  const fs::path out = FreshDir("interrupted");
  Write((out / "earlier.txt").string(), "an earlier run's");
  std::optional<StagingDirectory> staging;
  int failures = 0;
  bool was_interrupted = false;
  VerbHooks hooks;
  hooks.on_failure = [&](bool interrupted) {
    ++failures;
    was_interrupted = interrupted;
    EXPECT_FALSE(staging.has_value());  // removed first
  };
  const VerbOutcome outcome = RunStaged(
      out.string(), staging,
      [&] {
        staging.emplace(out.string());
        Write(staging->path("a.txt"), "a");
        throw Interrupted(SIGINT);
      },
      hooks);
  EXPECT_EQ(outcome.code, 130);
  EXPECT_EQ(outcome.message, "interrupted by SIGINT; removed this run's temporary files, " +
                                 out.string() + " is as it was before the run");
  EXPECT_EQ(failures, 1);
  EXPECT_TRUE(was_interrupted);
  EXPECT_EQ(Entries(out), std::vector<std::string>{"earlier.txt"});

  hooks.interrupted_message = [](const Interrupted& e) { return std::string(e.what()) + "!"; };
  EXPECT_EQ(RunStaged(
                out.string(), staging, [] { throw Interrupted(SIGTERM); }, hooks)
                .message,
            "interrupted by SIGTERM!");
}

TEST(RunStaged, AFailedRunNamesTheFileItWasWritingInOut) {
  const fs::path out = FreshDir("failed");
  std::optional<StagingDirectory> staging;
  const VerbOutcome outcome = RunStaged(out.string(), staging, [&] {
    staging.emplace(out.string());
    throw std::runtime_error("cannot write " + staging->path("rocks.csv") + ": disk full");
  });
  EXPECT_EQ(outcome.code, kExitRunFailed);
  EXPECT_EQ(outcome.message,
            "cannot write " + (out / "rocks.csv").string() + ": disk full (no output written)");
  EXPECT_TRUE(Entries(out).empty());
  // Before any staging directory: the message as it is.
  EXPECT_EQ(RunStaged(out.string(), staging, [] { throw std::runtime_error("no memory"); }).message,
            "no memory (no output written)");
}

TEST(RunStaged, LateBadInputIsBadInputWhenTheVerbSaysSo) {
  const fs::path out = FreshDir("late_input");
  std::optional<StagingDirectory> staging;
  const auto work = [&] {
    staging.emplace(out.string());
    throw InputError("blocks.csv:3: shape: cannot be built");
  };
  EXPECT_EQ(RunStaged(out.string(), staging, work).code, kExitRunFailed);
  VerbHooks hooks;
  hooks.late_input_errors = true;
  const VerbOutcome outcome = RunStaged(out.string(), staging, work, hooks);
  EXPECT_EQ(outcome.code, kExitBadInput);
  EXPECT_EQ(outcome.message, "blocks.csv:3: shape: cannot be built (no output written)");
  EXPECT_TRUE(Entries(out).empty());
}

TEST(RunVerb, BadOutOrFailedChecksAreBadInputBeforeAnyWork) {
  const fs::path dir = FreshDir("verb");
  Write((dir / "file").string(), "");
  bool worked = false;
  const auto work = [&](std::optional<StagingDirectory>&) { worked = true; };
  testing::internal::CaptureStderr();
  EXPECT_EQ(RunVerb({.name = "simulate", .out = (dir / "file").string()}, work), kExitBadInput);
  EXPECT_EQ(
      testing::internal::GetCapturedStderr(),
      "talus simulate: --out " + (dir / "file").string() + " exists and is not a directory\n");
  Verb verb{.name = "simulate", .out = (dir / "out").string()};
  verb.checks = [] { return std::string("needs about 2 TB of disk"); };
  testing::internal::CaptureStderr();
  EXPECT_EQ(RunVerb(verb, work), kExitBadInput);
  EXPECT_EQ(testing::internal::GetCapturedStderr(), "talus simulate: needs about 2 TB of disk\n");
  EXPECT_FALSE(worked);
}

TEST(RunVerb, RunsTheWorkAndSaysAFailureOnStderr) {
  const fs::path out = FreshDir("verb_run") / "out";  // created by the verb
  Verb verb{.name = "merge", .out = out.string()};
  EXPECT_EQ(RunVerb(verb,
                    [&](std::optional<StagingDirectory>& staging) {
                      staging.emplace(out.string());
                      Write(staging->path("summary.json"), "{}");
                      staging->Commit({"summary.json"});
                    }),
            kExitOk);
  EXPECT_EQ(Entries(out), std::vector<std::string>{"summary.json"});
  testing::internal::CaptureStderr();
  EXPECT_EQ(RunVerb(verb, [](std::optional<StagingDirectory>&) { throw Interrupted(SIGTERM); }),
            143);
  EXPECT_EQ(testing::internal::GetCapturedStderr(),
            "talus merge: interrupted by SIGTERM; removed this run's temporary files, " +
                out.string() + " is as it was before the run\n");
  EXPECT_EQ(Entries(out), std::vector<std::string>{"summary.json"});
}

}  // namespace
}  // namespace talus::app
