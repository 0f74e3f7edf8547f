#include "io/validate_event.hpp"

#include <chrono>

#include "ensemble/runner.hpp"
#include "talus/version.hpp"

namespace talus::io {

EventValidation ValidateEvent(const EventFile& event, const EventValidationOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  const ensemble::ReleaseSpec& release = event.scene.release;
  const auto say = [&options](const std::string& line) {
    if (options.say) options.say(line);
  };
  ensemble::EnsembleOptions run_options;
  run_options.threads = options.threads;
  run_options.episodes = event.needs_episodes;
  run_options.progress = options.progress;
  // Trajectory segments and zones: what each rock gives for them.
  fieldobs::AddRecordersFor(event.observations, event.scene.scene.terrain, release, run_options);

  EventValidation out;
  out.simulated = std::make_unique<fieldobs::EnsembleSamples>(release);
  out.run.ensemble =
      ensemble::RunEnsemble(event.scene.scene, release, run_options, out.simulated.get());
  say("Simulated: " + out.run.ensemble.BriefReport());

  // The reference parameter set: the same rocks again, when it differs from the scene's.
  const fieldobs::EnsembleSamples* reference = nullptr;
  if (event.reference == "table1") {
    bool differs = false;
    GroundTable table = ReferenceGround(event.scene.scene.ground, &differs);
    reference = out.simulated.get();
    if (differs) {
      Scene scene = event.scene.scene;
      scene.ground = std::move(table);
      out.reference = std::make_unique<fieldobs::EnsembleSamples>(release);
      const ensemble::EnsembleReport r =
          ensemble::RunEnsemble(scene, release, run_options, out.reference.get());
      say("Reference (Table 1): " + r.BriefReport());
      reference = out.reference.get();
      out.run.reference_run = true;
    }
  }
  fieldobs::ValidationOptions validation;
  validation.seed = release.seed;
  out.report = fieldobs::Validate(event.observations, *out.simulated, reference, validation);

  out.run.version = kVersion;
  out.run.rocks_per_run = release.rocks_per_release;
  out.run.seed = release.seed;
  out.run.threads = out.run.ensemble.threads;
  out.run.wall_time_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

}  // namespace talus::io
