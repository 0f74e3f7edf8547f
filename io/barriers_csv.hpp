#pragma once
// The outputs of barriers (docs/scenes.md, "[[barriers]]"): barriers.csv, one row per rock and
// barrier it reached, streamed in rock order and complete or absent; and the per-barrier summary
// (barriers_summary.csv, summary.json, report.html), computed from that file read back once it is
// complete, so that a run split into parts or ranks gives the same numbers (as evaluation lines).

#include <string>
#include <vector>

#include "common/atomic_file.hpp"
#include "ensemble/outcome.hpp"
#include "ensemble/release.hpp"
#include "io/evaluation_lines_csv.hpp"
#include "solver/barriers.hpp"

namespace talus::io {

class BarriersCsvWriter {
 public:
  // Opens a temporary file next to `path` and writes the header. `barriers` and `release` name
  // each row's barrier and run; both must outlive the writer. Throws std::runtime_error.
  BarriersCsvWriter(const std::string& path, const std::vector<Barrier>& barriers,
                    const ensemble::ReleaseSpec& release);
  BarriersCsvWriter(const BarriersCsvWriter&) = delete;
  BarriersCsvWriter& operator=(const BarriersCsvWriter&) = delete;

  // A row per barrier the rock reached (RockResult::barrier_events), in the order it reached them.
  void Write(const ensemble::RockOutcome& rock);
  void Commit();  // flushes, closes and renames into place

  static const char* Header();

 private:
  AtomicTextFile file_;
  const std::vector<Barrier>& barriers_;
  const ensemble::ReleaseSpec& release_;
};

// One barrier's summary over the rocks of a run. Statistics as evaluation lines' (mean,
// nearest-rank percentiles, largest; NaN when no rock is counted).
struct BarrierSummary {
  std::string name;
  std::string type;  // ToString(BarrierType)
  double length_m = 0, height_m = 0, capacity_J = 0;
  long rocks = 0;                  // rocks of the run
  long reached = 0;                // rocks that reached it (crossed its line)
  long stopped = 0;                // ... and were stopped there
  long overtopped = 0;             // ... and passed above it
  long broke_through = 0;          // ... and broke through it with energy_J - capacity
  double reach_probability = 0;    // reached / rocks
  double passing_probability = 0;  // (overtopped + broke_through) / rocks
  // Over the rocks that reached it: kinetic energy at the crossing (before the barrier acted)
  // and passing height (lowest hull vertex above the terrain).
  CrossingStatistics impact_energy_J, passing_height_m;
  // Over the rocks that passed (overtopped or broke through): kinetic energy after the barrier.
  CrossingStatistics passing_energy_J;
};

// The summary of every barrier from a complete barriers.csv of a run of `rocks` rocks, read row by
// row, and again as SummarizeColumns (common/column_statistics.hpp) needs: memory is bounded by
// `budget_bytes`, not by the rows. Throws InputError naming the file and line when a row is not one
// the writer writes.
std::vector<BarrierSummary> SummarizeBarriers(
    const std::string& csv_path, const std::vector<Barrier>& barriers, long rocks,
    std::size_t budget_bytes = kColumnStatisticsBudgetBytes);

// barriers_summary.csv: a header and one row per barrier.
std::string BarriersSummaryCsv(const std::vector<BarrierSummary>& summary);

}  // namespace talus::io
