// talus merge: combines the partial results of `talus simulate --rock-range` into the outputs of
// one run of all rocks (io/partial.hpp, docs/cluster.md).

#include <algorithm>
#include <filesystem>
#include <functional>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "app/commands.hpp"
#include "app/console.hpp"
#include "app/interrupt.hpp"
#include "app/run_outputs.hpp"
#include "app/run_verb.hpp"
#include "app/simulate.hpp"
#include "common/error.hpp"

namespace talus::app {
namespace {

struct MergeArgs {
  std::vector<std::string> parts;
  std::string out;
};

int RunMerge(const MergeArgs& args) {
  namespace fs = std::filesystem;
  std::vector<io::PartialInfo> parts;
  io::SceneFile scene;
  // On a terminal: checking the parts (every byte is read for its checksum), then each output
  // merged and written. A message (Say, Fail) starts on a line of its own.
  PhaseProgress progress;
  try {
    for (const std::string& dir : args.parts) {
      std::error_code error;
      if (fs::equivalent(dir, args.out, error))
        throw InputError("--out " + args.out +
                         " is one of the parts; merge into another directory");
    }
    parts = ReadParts(args.parts, std::ref(progress));
    scene = LoadSceneOfPart(parts.front());
  } catch (const InputError& e) {
    Fail("merge", e.what());
    return kExitBadInput;
  } catch (const std::exception& e) {
    Fail("merge", e.what());
    return kExitRunFailed;
  }
  return RunVerb({.name = "merge", .out = args.out}, [&](std::optional<StagingDirectory>& staging) {
    staging.emplace(args.out);
    // The threads and wall time of the parts, for the summary: the most threads any part used and
    // the sum of the parts' wall times.
    int threads = 1;
    double wall_time_s = 0;
    for (const io::PartialInfo& p : parts) {
      threads = std::max(threads, p.counts.threads);
      wall_time_s += p.counts.wall_time_s;
    }
    ensemble::EnsembleReport report;
    const std::vector<std::string> files =
        MergeIntoStaging(scene, parts, threads, wall_time_s, *staging, &report, std::ref(progress));
    progress.Break();
    CommitOutputs(*staging, files, args.out);
    Say("Merged %zu parts of %s: %s\n", parts.size(), scene.path.c_str(),
        report.BriefReport().c_str());
    Say("Wrote %zu files to %s\n", files.size(), args.out.c_str());
    PrintRunWarnings(report, scene, "merge");
  });
}

}  // namespace

Runner AddMergeCommand(CLI::App& app) {
  auto args = std::make_shared<MergeArgs>();
  CLI::App* cmd = app.add_subcommand(
      "merge", "Combine partial results of talus simulate --rock-range into one run's outputs");
  cmd->add_option("parts", args->parts, "Directories of the partial results, in any order")
      ->required();
  cmd->add_option("--out", args->out, "Output directory")->required();
  return [cmd, args]() { return *cmd ? RunMerge(*args) : -1; };
}

}  // namespace talus::app
