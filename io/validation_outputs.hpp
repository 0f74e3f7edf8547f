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

std::string ScoresJson(const EventFile& event, const fieldobs::ValidationReport& report,
                       const ValidationRun& run);
// Per block and kind: scored count, mean bias (simulated mean - observed) and mean score.
nlohmann::ordered_json BlockBiasJson(const std::vector<fieldobs::BlockBias>& biases);
std::string ObservationsCsv(const fieldobs::ValidationReport& report);
std::string ObservedVsSimulatedSvg(const fieldobs::ValidationReport& report);
std::string PitSvg(const fieldobs::ValidationReport& report);

// Writes text to `path` completely or not at all. Throws std::runtime_error.
void WriteTextFile(const std::string& path, const std::string& text);

// deposits.png: the DEM's hillshade, simulated end positions (blue) and observed rest positions
// (red), when the event has deposit observations.
void WriteDepositsPng(const std::string& path, const EventFile& event,
                      const fieldobs::EnsembleSamples& simulated);

}  // namespace talus::io
