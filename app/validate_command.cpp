// talus validate: how well does a parameter set explain what was observed? Runs an event's scene
// (its runs, with an ensemble of orientations each), scores the simulated counterparts of every
// observation and writes scores.json, observations.csv and the plots (docs/validation.md).

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>

#include "app/commands.hpp"
#include "common/error.hpp"
#include "fieldobs/samples.hpp"
#include "fieldobs/validation.hpp"
#include "io/event_file.hpp"
#include "io/validation_outputs.hpp"
#include "talus/version.hpp"

namespace talus::app {
namespace {

struct ValidateArgs {
  std::string event;
  std::string out;
  long rocks = 0;  // per run; 0: the scene's
  int threads = 0;
  std::optional<std::uint64_t> seed;
};

int RunValidate(const ValidateArgs& args) {
  namespace fs = std::filesystem;
  const auto t0 = std::chrono::steady_clock::now();
  io::EventFile event;
  try {
    event = io::LoadEvent(args.event);
  } catch (const InputError& e) {
    std::cerr << "talus validate: " << e.what() << "\n";
    return 2;
  }
  ensemble::ReleaseSpec& release = event.scene.release;
  if (args.rocks > 0) release.rocks_per_release = args.rocks;
  if (args.seed) release.seed = *args.seed;
  std::string why;
  if (!release.IsValid(&why)) {
    std::cerr << "talus validate: " << args.event << ": " << why << "\n";
    return 2;
  }
  std::error_code error;
  fs::create_directories(args.out, error);
  if (error || !fs::is_directory(args.out)) {
    std::cerr << "talus validate: cannot create the output directory " << args.out << ": "
              << error.message() << "\n";
    return 2;
  }
  const auto out = [&](const std::string& name) { return (fs::path(args.out) / name).string(); };
  std::printf("Event %s: %zu observations (%zu scalar, %zu deposits) of %ld runs x %ld rocks\n",
              args.event.c_str(), event.observations.size(), event.observations.scalars.size(),
              event.observations.deposits.size(), release.release_count(),
              release.rocks_per_release);
  try {
    ensemble::EnsembleOptions options;
    options.threads = args.threads;
    options.episodes = event.needs_episodes;
    fieldobs::EnsembleSamples simulated(release);
    io::ValidationRun run;
    run.ensemble = ensemble::RunEnsemble(event.scene.scene, release, options, &simulated);
    std::printf("Simulated: %s\n", run.ensemble.BriefReport().c_str());

    // The reference parameter set: the same rocks again, when it differs from the scene's.
    std::optional<fieldobs::EnsembleSamples> reference;
    const fieldobs::EnsembleSamples* reference_samples = nullptr;
    if (event.reference == "table1") {
      bool differs = false;
      GroundTable table = io::ReferenceGround(event.scene.scene.ground, &differs);
      reference_samples = &simulated;
      if (differs) {
        Scene scene = event.scene.scene;
        scene.ground = std::move(table);
        reference.emplace(release);
        const ensemble::EnsembleReport r =
            ensemble::RunEnsemble(scene, release, options, &*reference);
        std::printf("Reference (Table 1): %s\n", r.BriefReport().c_str());
        reference_samples = &*reference;
        run.reference_run = true;
      }
    }
    fieldobs::ValidationOptions validation;
    validation.seed = release.seed;
    const fieldobs::ValidationReport report =
        fieldobs::Validate(event.observations, simulated, reference_samples, validation);

    run.version = kVersion;
    run.rocks_per_run = release.rocks_per_release;
    run.seed = release.seed;
    run.threads = run.ensemble.threads;
    run.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    io::WriteTextFile(out("observations.csv"), io::ObservationsCsv(report));
    io::WriteTextFile(out("observed_vs_simulated.svg"), io::ObservedVsSimulatedSvg(report));
    io::WriteTextFile(out("pit.svg"), io::PitSvg(report));
    int files = 4;
    if (!event.observations.deposits.empty()) {
      io::WriteDepositsPng(out("deposits.png"), event, simulated);
      ++files;
    }
    io::WriteTextFile(out("scores.json"), io::ScoresJson(event, report, run));
    std::printf("%s", report.FullReport().c_str());
    std::printf("Wrote %d files to %s\n", files, args.out.c_str());
    return 0;
  } catch (const InputError& e) {
    std::cerr << "talus validate: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "talus validate: " << e.what() << "\n";
    return 1;
  }
}

}  // namespace

Runner AddValidateCommand(CLI::App& app) {
  auto args = std::make_shared<ValidateArgs>();
  CLI::App* cmd = app.add_subcommand(
      "validate", "Score a scene's simulated rocks against an event's field observations");
  cmd->add_option("event", args->event, "Event file (TOML): scene and observation tables")
      ->required();
  cmd->add_option("--out", args->out, "Output directory")->required();
  cmd->add_option("--rocks", args->rocks, "Rocks per run (overrides the scene)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--threads", args->threads, "Worker threads (default: all cores)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option_function<std::uint64_t>(
      "--seed", [args](const std::uint64_t& seed) { args->seed = seed; },
      "Random seed (overrides the scene)");
  return [cmd, args]() { return *cmd ? RunValidate(*args) : -1; };
}

}  // namespace talus::app
