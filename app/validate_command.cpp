// talus validate: how well does a parameter set explain what was observed? Runs an event's scene
// (its runs, with an ensemble of orientations each), scores the simulated counterparts of every
// observation and writes scores.json, observations.csv, the plots and report.html
// (docs/validation.md).

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <limits>
#include <memory>
#include <optional>

#include "app/commands.hpp"
#include "app/console.hpp"
#include "app/ensemble_args.hpp"
#include "app/interrupt.hpp"
#include "app/run_verb.hpp"
#include "app/simulate.hpp"
#include "common/atomic_file.hpp"
#include "common/error.hpp"
#include "fieldobs/samples.hpp"
#include "fieldobs/validation.hpp"
#include "io/event_file.hpp"
#include "io/validate_event.hpp"
#include "io/validation_outputs.hpp"
#include "io/validation_report_html.hpp"
#include "talus/version.hpp"

namespace talus::app {
namespace {

struct ValidateArgs {
  std::string event;
  std::string out;
  EnsembleArgs ensemble;  // --rocks (per run), --threads, --seed
};

int RunValidate(const ValidateArgs& args) {
  const auto t0 = std::chrono::steady_clock::now();
  io::EventFile event;
  try {
    event = io::LoadEvent(args.event);
    args.ensemble.ApplyTo(event.scene.release);
  } catch (const InputError& e) {
    Fail("validate", e.what());
    return kExitBadInput;
  } catch (const std::exception& e) {
    Fail("validate", "cannot load " + args.event + ": " + e.what());
    return kExitRunFailed;
  }
  Verb verb{.name = "validate", .out = args.out};
  verb.hooks.late_input_errors = true;  // a shape per rock that cannot be built, found late
  return RunVerb(verb, [&](std::optional<StagingDirectory>& staging) {
    PrintSceneWarnings(event.scene, "validate");
    const ensemble::ReleaseSpec& release = event.scene.release;
    Say("Event %s: %zu observations (%zu scalar, %zu deposits) of %ld runs x %ld rocks\n",
        args.event.c_str(), event.observations.size(), event.observations.scalars.size(),
        event.observations.deposits.size(), release.release_count(), release.rocks_per_release);
    PrintNotScored(event.not_scored);
    // Every output is staged and moved into --out only when all are complete.
    staging.emplace(args.out);
    const auto out = [&](const std::string& name) { return staging->path(name); };
    io::EventValidationOptions options;
    options.threads = args.ensemble.threads;
    ProgressBar progress;  // the runs' rocks, on a terminal
    options.progress = [&progress](long done, long total) {
      ThrowIfInterrupted();
      progress(done, total);
    };
    options.say = [&progress](const std::string& line) {
      progress.Break();
      Say("%s\n", line.c_str());
    };
    const io::EventValidation validation = io::ValidateEvent(event, options);
    const fieldobs::ValidationReport& report = validation.report;
    const fieldobs::EnsembleSamples& simulated = *validation.simulated;
    io::ValidationRun run = validation.run;
    run.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::vector<std::string> outputs = {"observations.csv", "observed_vs_simulated.svg", "pit.svg"};
    io::WriteTextFile(out("observations.csv"), io::ObservationsCsv(report));
    io::WriteTextFile(out("observed_vs_simulated.svg"), io::ObservedVsSimulatedSvg(report));
    io::WriteTextFile(out("pit.svg"), io::PitSvg(report));
    std::string deposits;
    if (!event.observations.deposits.empty()) {
      deposits = io::DepositsPng(event, simulated);
      WriteFileAtomically(out("deposits.png"), deposits);
      outputs.push_back("deposits.png");
    }
    const std::string scores = io::ScoresJson(event, report, run);
    WriteFileAtomically(out("report.html"), io::ValidationReportHtml({scores, &report, deposits}));
    outputs.push_back("report.html");
    io::WriteTextFile(out("scores.json"), scores);
    outputs.push_back("scores.json");  // last: scores.json is there only with its outputs
    ThrowIfInterrupted();
    staging->Commit(outputs);
    Say("%s", report.FullReport().c_str());
    Say("Wrote %zu files to %s\n", outputs.size(), args.out.c_str());
    // The scene's were printed before the run.
    const std::vector<std::string> warnings = io::ValidationWarnings(event, run);
    for (std::size_t k = event.scene.warnings.size(); k < warnings.size(); ++k)
      Warn("validate", warnings[k]);
  });
}

}  // namespace

Runner AddValidateCommand(CLI::App& app) {
  auto args = std::make_shared<ValidateArgs>();
  CLI::App* cmd = app.add_subcommand(
      "validate", "Score a scene's simulated rocks against an event's field observations");
  cmd->add_option("event", args->event, "Event file (TOML): scene and observation tables")
      ->required();
  cmd->add_option("--out", args->out, "Output directory")->required();
  AddEnsembleOptions(cmd, &args->ensemble, "run");
  return [cmd, args]() { return *cmd ? RunValidate(*args) : -1; };
}

}  // namespace talus::app
