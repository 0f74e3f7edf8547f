#pragma once
// One validation, end to end, in one call: what `talus validate` runs and what the Python module
// runs. The event's scene is run (its runs, an ensemble of orientations each), and again with the
// reference table when that differs from the scene's; every observation is scored against its
// simulated counterparts (fieldobs::Validate). Files and printing stay with the caller.

#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "fieldobs/samples.hpp"
#include "fieldobs/validation.hpp"
#include "io/event_file.hpp"
#include "io/validation_outputs.hpp"

namespace talus::io {

struct EventValidationOptions {
  int threads = 0;  // worker threads; 0: all cores
  // Called on the calling thread while rocks run (rocks done, total); may throw to stop.
  std::function<void(long, long)> progress;
  // One line for people after each ensemble ("Simulated: ...", "Reference (Table 1): ...").
  std::function<void(const std::string& line)> say;
};

// What a validation gave. The samples refer to the event's release: the event must outlive them.
struct EventValidation {
  std::unique_ptr<fieldobs::EnsembleSamples> simulated;
  std::unique_ptr<fieldobs::EnsembleSamples> reference;  // null when the reference was not run
  fieldobs::ValidationReport report;
  ValidationRun run;  // version, rocks, seed, threads and the ensemble's counts; wall time so far
};

// Runs and scores `event` as talus validate does. Throws what the ensemble and the callbacks
// throw (talus::InputError for a shape per rock that cannot be built).
EventValidation ValidateEvent(const EventFile& event, const EventValidationOptions& options);

}  // namespace talus::io
