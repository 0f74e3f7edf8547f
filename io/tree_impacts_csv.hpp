#pragma once
// The outputs of a forest (docs/scenes.md, "[forest]"): tree_impacts.csv, one row per rock and
// stem it touched, streamed in rock order and complete or absent; and the forest's summary
// (summary.json), computed from that file read back once it is complete, so that a run split into
// parts or ranks gives the same numbers (as barriers).

#include <string>

#include "common/atomic_file.hpp"
#include "ensemble/outcome.hpp"
#include "ensemble/release.hpp"
#include "solver/forest.hpp"

namespace talus::io {

class TreeImpactsCsvWriter {
 public:
  // Opens a temporary file next to `path` and writes the header. `forest` and `release` must
  // outlive the writer. Throws std::runtime_error.
  TreeImpactsCsvWriter(const std::string& path, const Forest& forest,
                       const ensemble::ReleaseSpec& release);
  TreeImpactsCsvWriter(const TreeImpactsCsvWriter&) = delete;
  TreeImpactsCsvWriter& operator=(const TreeImpactsCsvWriter&) = delete;

  // A row per stem the rock touched (RockResult::stem_hits), in the order it first hit them.
  void Write(const ensemble::RockOutcome& rock);
  void Commit();  // flushes, closes and renames into place

  static const char* Header();

 private:
  AtomicTextFile file_;
  const Forest& forest_;
  const ensemble::ReleaseSpec& release_;
};

// What the stems did over a run, from a complete tree_impacts.csv.
struct TreeImpactSummary {
  long rows = 0;            // (rock, stem) pairs
  long impacts = 0;         // contact episodes, summed
  long rocks_hitting = 0;   // rocks that touched at least one stem
  long rocks_breaking = 0;  // rocks that broke at least one stem
  long breakages = 0;       // (rock, stem) pairs where the rock broke the stem
  long stems_hit = 0;       // distinct stems touched by any rock
  double absorbed_J = 0;    // energy taken by the stems, summed over rows
};
// Throws InputError naming the file and line when a row is malformed.
TreeImpactSummary SummarizeTreeImpacts(const std::string& csv_path);

}  // namespace talus::io
