// talus calibrate: fit ground parameters to an event's observations (docs/calibration.md). Loads
// and checks the calibration file, its event, scene and observations before any rock runs; runs
// the optimiser on the same rocks again and again (common random numbers); measures the
// objective's roughness and each parameter's profile at the optimum; writes the fitted ground
// table, calibration.json and history.csv, all complete or none.

#include <unistd.h>

#include <chrono>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <limits>
#include <memory>
#include <optional>

#include "app/commands.hpp"
#include "app/interrupt.hpp"
#include "calibration/objective.hpp"
#include "calibration/optimizer.hpp"
#include "calibration/roughness.hpp"
#include "common/atomic_file.hpp"
#include "common/error.hpp"
#include "io/calibration_file.hpp"
#include "io/calibration_outputs.hpp"
#include "talus/version.hpp"

namespace talus::app {
namespace {

struct CalibrateArgs {
  std::string file;
  std::string out;
  int threads = 0;
};

const std::vector<std::string> kOutputs = {"ground_table.toml", "ground_table.csv", "history.csv",
                                           "calibration.json"};

int RunCalibrate(const CalibrateArgs& args) {
  namespace fs = std::filesystem;
  const auto t0 = std::chrono::steady_clock::now();
  io::CalibrationFile file;
  std::unique_ptr<calibration::Objective> objective;
  try {
    file = io::LoadCalibration(args.file);
    calibration::ObjectiveOptions options = file.objective;
    options.threads = args.threads;
    options.progress = [](long, long) { ThrowIfInterrupted(); };
    const io::EventFile& event = file.event;
    objective = std::make_unique<calibration::Objective>(
        event.scene.scene, event.scene.release, event.observations, file.parameters, options);
  } catch (const InputError& e) {
    std::cerr << "talus calibrate: " << e.what() << "\n";
    return kExitBadInput;
  } catch (const std::exception& e) {
    std::cerr << "talus calibrate: cannot load " << args.file << ": " << e.what() << "\n";
    return kExitRunFailed;
  }
  if (const std::string why = PrepareOutputDirectory(args.out); !why.empty()) {
    std::cerr << "talus calibrate: " << why << "\n";
    return kExitBadInput;
  }
  const InterruptScope interrupts;
  std::signal(SIGXFSZ, SIG_IGN);
  RemoveStaleTemporaries(args.out);

  const ensemble::ReleaseSpec& release = objective->release();
  std::printf("Calibration %s: %d parameters, %zu observations of %ld runs x %ld rocks, %s\n",
              args.file.c_str(), objective->dimension(), file.event.observations.size(),
              release.release_count(), release.rocks_per_release, file.optimizer.algorithm.c_str());
  std::fflush(stdout);
  std::optional<StagingDirectory> staging;
  try {
    calibration::OptimizerOptions options = file.optimizer;
    const bool terminal = ::isatty(STDOUT_FILENO) != 0;
    options.on_evaluation = [&](const calibration::Evaluation& e, int index) {
      ThrowIfInterrupted();
      std::printf("%s  evaluation %4d  objective %-12.6g %s%s", terminal ? "\r" : "", index,
                  e.value, e.feasible ? "" : "(infeasible)", terminal ? "   " : "\n");
      std::fflush(stdout);
    };
    io::CalibrationRun run;
    run.version = kVersion;
    run.summary = calibration::Calibrate(*objective, options);
    if (terminal) std::printf("\n");
    std::printf("%s", run.summary.FullReport().c_str());
    if (!run.summary.IsSolutionUsable()) {
      std::cerr << "talus calibrate: " << run.summary.message << " (no output written)\n";
      return kExitRunFailed;
    }
    if (file.roughness) {
      std::printf("Measuring the roughness and the profiles at the optimum...\n");
      std::fflush(stdout);
      run.roughness =
          calibration::MeasureRoughness(*objective, run.summary.best.u, file.roughness_options);
      const auto t1 = std::chrono::steady_clock::now();
      run.profiles =
          calibration::ProfileParameters(*objective, run.summary.best.u, run.summary.best.value,
                                         run.roughness->level(), file.profile_options);
      run.roughness->wall_time_s +=
          std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
      std::printf("%s", run.roughness->Report().c_str());
      for (const calibration::ParameterProfile& p : run.profiles)
        std::printf(
            "  %-28s profile range %-10.3g threshold %-10.3g %s\n", p.name.c_str(), p.range,
            p.threshold,
            p.identified ? "identified" : "UNIDENTIFIED: the observations do not constrain it");
    }
    run.threads = args.threads;
    run.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

    ThrowIfInterrupted();
    staging.emplace(args.out);
    const GroundTable fitted = objective->GroundOf(run.summary.best.u);
    WriteFileAtomically(staging->path("ground_table.toml"),
                        io::GroundTableToml(file, *objective, fitted));
    WriteFileAtomically(staging->path("ground_table.csv"), io::GroundTableCsv(*objective, fitted));
    WriteFileAtomically(staging->path("history.csv"), io::HistoryCsv(*objective, run.summary));
    WriteFileAtomically(staging->path("calibration.json"),
                        io::CalibrationJson(file, *objective, run));
    ThrowIfInterrupted();
    staging->Commit(kOutputs);  // calibration.json last
    std::printf("Wrote %zu files to %s in %.1f s\n", kOutputs.size(), args.out.c_str(),
                run.wall_time_s);
    return kExitOk;
  } catch (const Interrupted& e) {
    staging.reset();
    std::cerr << "\ntalus calibrate: " << e.what() << "; no output written, " << args.out
              << " is as it was before the run\n";
    return ExitCodeForSignal(e.signal());
  } catch (const std::exception& e) {
    const std::string message = staging ? staging->Describe(e.what()) : e.what();
    staging.reset();
    std::cerr << "talus calibrate: " << message << " (no output written)\n";
    return kExitRunFailed;
  }
}

}  // namespace

Runner AddCalibrateCommand(CLI::App& app) {
  auto args = std::make_shared<CalibrateArgs>();
  CLI::App* cmd = app.add_subcommand(
      "calibrate", "Fit ground parameters to an event's field observations (CAL.toml)");
  cmd->add_option("calibration", args->file,
                  "Calibration file (TOML): event, free parameters, optimiser")
      ->required();
  cmd->add_option("--out", args->out, "Output directory")->required();
  cmd->add_option("--threads", args->threads, "Worker threads (default: all cores)")
      ->check(ThreadCount());
  return [cmd, args]() { return *cmd ? RunCalibrate(*args) : -1; };
}

}  // namespace talus::app
