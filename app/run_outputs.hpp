#pragma once
// The outputs of a simulation run, shared by `talus simulate` (one process, a part of the rocks,
// or MPI ranks) and `talus merge`: running rocks into a staging directory as a whole run or as a
// part (io/partial.hpp), merging parts, and writing the rasters, quick-look and summary.json.

#include <chrono>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "common/atomic_file.hpp"
#include "ensemble/runner.hpp"
#include "ensemble/self_check.hpp"
#include "io/partial.hpp"
#include "io/scene_file.hpp"

namespace talus::app {

// The rocks whose paths the quick-look draws: the first rocks of every release (of every k-th
// release when there are more than 100), about 40 in all and at least one per release drawn.
bool QuickLookSample(const ensemble::ReleaseSpec& release, long rock);

// Every file name talus simulate and merge may write into an output directory.
std::vector<std::string> TalusOutputNames();

// Runs rocks [first_rock, end_rock) of the scene and writes them into `staging`: rocks.csv and
// trajectories.h5 (when asked); then, as a `part`, partial.bin and partial.json, else (the whole
// ensemble) the rasters, quick-look and summary.json. Returns the files written, in commit order.
// `progress` is called on the calling thread (and may throw to stop the run). A self-check's
// report, when given, goes into summary.json.
std::vector<std::string> RunIntoStaging(const io::SceneFile& scene, int threads, long first_rock,
                                        long end_rock, bool part, const StagingDirectory& staging,
                                        std::function<void(long, long)> progress,
                                        ensemble::EnsembleReport* report,
                                        const ensemble::SelfCheckReport* self_check = nullptr);

// What a merge is doing, for a progress line: `done` of `total` `unit`s ("bytes", "parts",
// "rocks", "files") of `phase` ("Checking the parts", "Merging trajectories.h5", ...).
using MergeProgress =
    std::function<void(const std::string& phase, long done, long total, const char* unit)>;

// A MergeProgress for the terminal: one status line through the phases, "<phase> [####      ]
// 3/8 parts  1.2/s  4 s left" (bytes shown as MB), each phase with its own rate, redrawn at most
// ten times a second; nothing off a terminal or with --quiet (console.hpp). What is said next
// (Say) starts on a line of its own; Break ends the line before a message.
class PhaseProgress {
 public:
  PhaseProgress();
  void operator()(const std::string& phase, long done, long total, const char* unit);
  void Break();

 private:
  bool enabled_;
  std::string phase_;
  std::chrono::steady_clock::time_point start_, shown_;
};

// Reads the parts in `dirs` (their partial.json), checks that they tile one run (io::CheckPartials)
// and that each one's files are as it wrote them (io::CheckPartFiles: every byte is read for its
// checksum, which `progress` counts); returns them sorted by range. Throws InputError naming the
// part and what is wrong.
std::vector<io::PartialInfo> ReadParts(const std::vector<std::string>& dirs,
                                       const MergeProgress& progress = {});

// Merges parts that CheckPartials accepted into `staging`: rocks.csv, trajectories.h5, rasters,
// quick-look and summary.json, the same bytes as one run of all rocks (summary.json's threads and
// timings aside: `threads` and `wall_time_s` are written there). Returns the files written, in
// commit order; *report gets the merged counts. `progress`, when given, hears each phase.
std::vector<std::string> MergeIntoStaging(const io::SceneFile& scene,
                                          const std::vector<io::PartialInfo>& parts, int threads,
                                          double wall_time_s, const StagingDirectory& staging,
                                          ensemble::EnsembleReport* report,
                                          const MergeProgress& progress = {});

// The list of the files a run wrote into its output directory, one name per line: what the next
// run into the same directory may remove.
inline constexpr const char* kOutputManifest = ".talus-outputs";

// Commits the staged files into `dir`, removes the outputs of the earlier run there that this one
// did not replace (those its kOutputManifest lists, and only talus's output names: never a file
// the user made; printing how many) and writes this run's manifest: `files` and the run log.
void CommitOutputs(StagingDirectory& staging, const std::vector<std::string>& files,
                   const std::string& dir);

// The scene a part was run with, loaded again from its scene file (with the part's --rocks and
// --seed, and its scene path as given). Throws InputError when the scene's inputs changed since.
io::SceneFile LoadSceneOfPart(const io::PartialInfo& part);

// Parses "A:B" (0 <= A < B) into [A, B); throws InputError naming --rock-range.
std::pair<long, long> ParseRockRange(const std::string& text);

}  // namespace talus::app
