#pragma once
// What `talus validate` writes (docs/validation.md): scores.json (stable keys), observations.csv
// (one row per observation with its score), and plots a person reads at a glance:
// observed_vs_simulated.svg (per kind: each observation against its ensemble's 5-95 % band and
// median), pit.svg (PIT histogram per kind) and deposits.png (observed and simulated rest
// positions over the hillshade). Every file is written completely or not at all.

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "ensemble/runner.hpp"
#include "fieldobs/samples.hpp"
#include "fieldobs/validation.hpp"
#include "io/event_file.hpp"

namespace talus::io {

// What a validation run was, for scores.json.
struct ValidationRun {
  std::string version;
  long rocks_per_run = 0;
  std::uint64_t seed = 1;
  int threads = 1;
  double wall_time_s = 0;
  bool reference_run = false;  // the reference parameter set differed and was simulated
  ensemble::EnsembleReport ensemble;
};

// The scene's warnings and what the run's endings censor (ensemble::RunWarnings: rocks at
// max_time, rocks that left the DEM, ...), one sentence each: scores.json's "warnings", printed
// by talus validate and shown first in its report.html.
std::vector<std::string> ValidationWarnings(const EventFile& event, const ValidationRun& run);

std::string ScoresJson(const EventFile& event, const fieldobs::ValidationReport& report,
                       const ValidationRun& run);
// Per block and kind: scored count, mean bias (simulated mean - observed) and mean score.
nlohmann::ordered_json BlockBiasJson(const std::vector<fieldobs::BlockBias>& biases);
std::string ObservationsCsv(const fieldobs::ValidationReport& report);
// One plot per scored scalar kind (svg_plot.hpp's frame): each observation at its observed value
// with its simulated 5-95 % band and median, and the 1:1 line.
std::vector<std::string> ObservedVsSimulatedPanels(const fieldobs::ValidationReport& report);
// One PIT histogram per kind that has one.
std::vector<std::string> PitPanels(const fieldobs::ValidationReport& report);
// The panels above as one SVG file each.
std::string ObservedVsSimulatedSvg(const fieldobs::ValidationReport& report);
std::string PitSvg(const fieldobs::ValidationReport& report);

// Writes text to `path` completely or not at all. Throws std::runtime_error.
void WriteTextFile(const std::string& path, const std::string& text);

// deposits.png's bytes: the DEM's hillshade, simulated end positions (blue) and observed rest
// positions (red), when the event has deposit observations.
std::string DepositsPng(const EventFile& event, const fieldobs::EnsembleSamples& simulated);

}  // namespace talus::io
