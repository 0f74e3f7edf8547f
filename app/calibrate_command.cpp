// talus calibrate: fit ground parameters to an event's observations (docs/calibration.md). Loads
// and checks the calibration file, its event, scene and observations before any rock runs; runs
// the optimiser on the same rocks again and again (common random numbers); measures the
// objective's roughness, each parameter's profile and the covariance at the optimum; scores
// held-out runs (--holdout) and cross-validates by run (--folds); writes the fitted ground table,
// calibration.json and history.csv, all complete or none. Every evaluation goes to
// DIR/checkpoint.json as it comes, so that an interrupted calibration resumes (--resume) to the
// result an uninterrupted one gives.

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <limits>
#include <memory>
#include <optional>
#include <sstream>

#include "app/commands.hpp"
#include "app/interrupt.hpp"
#include "calibration/holdout.hpp"
#include "calibration/least_squares.hpp"
#include "calibration/objective.hpp"
#include "calibration/optimizer.hpp"
#include "calibration/roughness.hpp"
#include "common/atomic_file.hpp"
#include "common/error.hpp"
#include "io/calibration_checkpoint.hpp"
#include "io/calibration_file.hpp"
#include "io/calibration_outputs.hpp"
#include "io/calibration_plots.hpp"
#include "talus/version.hpp"

namespace talus::app {
namespace {

struct CalibrateArgs {
  std::string file;
  std::string out;
  int threads = 0;
  std::string holdout;  // a number of runs, or a comma-separated list of run ids
  int folds = 0;
  bool resume = false;
};

const char* kCheckpoint = "checkpoint.json";

// The held-out runs of --holdout: K runs drawn by the optimiser's seed, or the listed ids.
std::vector<std::string> HoldoutRuns(const std::string& text, const ensemble::ReleaseSpec& release,
                                     std::uint64_t seed) {
  if (text.empty()) return {};
  if (release.runs.empty())
    throw InputError("--holdout: the event's scene releases no runs ([release] runs)");
  if (text.find_first_not_of("0123456789") == std::string::npos)
    return calibration::PickRuns(release, std::stoi(text), seed);
  std::vector<std::string> ids;
  std::stringstream list(text);
  for (std::string id; std::getline(list, id, ',');) {
    id.erase(0, id.find_first_not_of(' '));
    id.erase(id.find_last_not_of(' ') + 1);
    bool known = false;
    for (const ensemble::ReleaseRun& r : release.runs) known = known || r.id == id;
    if (!known) throw InputError("--holdout: '" + id + "' is not a run of the event's scene");
    if (std::find(ids.begin(), ids.end(), id) != ids.end())
      throw InputError("--holdout: run '" + id + "' is listed twice");
    ids.push_back(id);
  }
  if (ids.size() >= release.runs.size())
    throw InputError("--holdout: every run is held out; nothing is left to fit");
  return calibration::OtherRuns(release, calibration::OtherRuns(release, ids));  // release order
}

std::string Join(const std::vector<std::string>& items) {
  std::string out;
  for (const std::string& s : items) out += (out.empty() ? "" : ", ") + s;
  return out;
}

int RunCalibrate(const CalibrateArgs& args) {
  namespace fs = std::filesystem;
  const auto t0 = std::chrono::steady_clock::now();
  io::CalibrationFile file;
  std::unique_ptr<calibration::Objective> objective;
  calibration::ObjectiveOptions objective_options;
  calibration::RunSubset fit;
  std::vector<std::string> holdout;
  std::vector<std::vector<std::string>> folds;
  io::CalibrationCheckpoint checkpoint;
  const std::string checkpoint_path = (fs::path(args.out) / kCheckpoint).string();
  try {
    file = io::LoadCalibration(args.file);
    objective_options = file.objective;
    objective_options.threads = args.threads;
    objective_options.progress = [](long, long) { ThrowIfInterrupted(); };
    const io::EventFile& event = file.event;
    holdout = HoldoutRuns(args.holdout, event.scene.release, file.optimizer.seed);
    fit = calibration::SelectRuns(event.scene.release, event.observations,
                                  calibration::OtherRuns(event.scene.release, holdout), true);
    if (args.folds > 0) {
      if (fit.release.runs.empty())
        throw InputError("--folds: the event's scene releases no runs ([release] runs)");
      folds = calibration::Folds(fit.release, args.folds, file.optimizer.seed);
    }
    objective = std::make_unique<calibration::Objective>(
        event.scene.scene, fit.release, fit.observations, file.parameters, objective_options);
    checkpoint.path_hash = file.path_hash;
    checkpoint.holdout = holdout;
    checkpoint.folds = args.folds;
    const bool exists = fs::exists(checkpoint_path);
    if (args.resume) {
      if (!exists) throw InputError("--resume: no " + checkpoint_path + " to resume from");
      const io::CalibrationCheckpoint saved = io::ReadCheckpoint(checkpoint_path);
      if (saved.path_hash != checkpoint.path_hash || saved.holdout != holdout ||
          saved.folds != args.folds)
        throw InputError(checkpoint_path +
                         ": the checkpoint belongs to another calibration (other inputs, "
                         "parameters, optimiser options, --holdout or --folds)");
      checkpoint.stages = saved.stages;
    } else if (exists) {
      throw InputError(checkpoint_path +
                       " holds the evaluations of an unfinished calibration: resume it with "
                       "--resume, or remove it");
    }
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

  const io::EventFile& event = file.event;
  const ensemble::ReleaseSpec& release = objective->release();
  std::printf("Calibration %s: %d parameters, %zu observations of %ld runs x %ld rocks, %s\n",
              args.file.c_str(), objective->dimension(), fit.observations.size(),
              release.release_count(), release.rocks_per_release, file.optimizer.algorithm.c_str());
  if (!holdout.empty())
    std::printf("Holding out %zu runs: %s\n", holdout.size(), Join(holdout).c_str());
  if (!checkpoint.stages.empty()) std::printf("Resuming from %s\n", checkpoint_path.c_str());
  std::fflush(stdout);
  const bool terminal = ::isatty(STDOUT_FILENO) != 0;
  // One optimisation, its evaluations replayed from and kept in the checkpoint.
  const auto optimise = [&](const calibration::Objective& target, const std::string& stage) {
    calibration::OptimizerOptions options = file.optimizer;
    options.replay = checkpoint.stages[stage];
    options.on_evaluation = [&, stage](const calibration::Evaluation& e, int index) {
      std::vector<calibration::Evaluation>& kept = checkpoint.stages[stage];
      if (index >= static_cast<int>(kept.size())) {
        kept.push_back(e);
        WriteFileAtomically(checkpoint_path, io::CheckpointJson(checkpoint));
      }
      ThrowIfInterrupted();
      std::printf("%s  %s evaluation %4d  objective %-12.6g %s%s", terminal ? "\r" : "",
                  stage.c_str(), index, e.value, e.feasible ? "" : "(infeasible)",
                  terminal ? "   " : "\n");
      std::fflush(stdout);
    };
    calibration::Summary summary = calibration::Calibrate(target, options);
    if (terminal) std::printf("\n");
    return summary;
  };
  const std::optional<GroundTable> reference =
      event.reference == "table1"
          ? std::optional<GroundTable>(io::ReferenceGround(event.scene.scene.ground, nullptr))
          : std::nullopt;

  std::optional<StagingDirectory> staging;
  try {
    io::CalibrationRun run;
    run.version = kVersion;
    run.summary = optimise(*objective, "fit");
    std::printf("%s", run.summary.FullReport().c_str());
    if (!run.summary.IsSolutionUsable()) {
      std::cerr << "talus calibrate: " << run.summary.message << " (no output written)\n";
      return kExitRunFailed;
    }
    const calibration::Evaluation& best = run.summary.best;
    if (file.roughness) {
      std::printf("Measuring the roughness and the profiles at the optimum...\n");
      std::fflush(stdout);
      run.roughness = calibration::MeasureRoughness(*objective, best.u, file.roughness_options);
      const auto t1 = std::chrono::steady_clock::now();
      run.profiles = calibration::ProfileParameters(*objective, best.u, best.value,
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
    if (file.uncertainty) {
      calibration::UncertaintyOptions options = file.uncertainty_options;
      if (!(options.fd_step > 0))
        options.fd_step = run.summary.fd_step > 0 ? run.summary.fd_step
                          : run.roughness         ? run.roughness->fd_step
                                                  : 0.01;
      options.noise = run.roughness ? run.roughness->level() : 0;
      options.profiles = run.profiles;
      std::printf("Estimating the covariance at the optimum...\n");
      std::fflush(stdout);
      run.uncertainty =
          calibration::EstimateUncertainty(*objective, best.u, options, run.summary.history);
      std::printf("%s", run.uncertainty->Report().c_str());
    }
    const GroundTable fitted = objective->GroundOf(best.u);
    // The fitted runs scored before and after, for the observed-vs-simulated plots.
    std::printf("Scoring the observations before and after for the plots...\n");
    std::fflush(stdout);
    const calibration::HeldOutScores before =
        calibration::ScoreRuns(event.scene.scene, fit, objective->GroundOf(run.summary.initial.u),
                               nullptr, args.threads, objective->needs_episodes());
    const calibration::HeldOutScores after = calibration::ScoreRuns(
        event.scene.scene, fit, fitted, nullptr, args.threads, objective->needs_episodes());
    if (!holdout.empty()) {
      std::printf("Scoring the %zu held-out runs...\n", holdout.size());
      std::fflush(stdout);
      run.holdout = calibration::ScoreRuns(
          event.scene.scene,
          calibration::SelectRuns(event.scene.release, event.observations, holdout, false), fitted,
          reference ? &*reference : nullptr, args.threads, objective->needs_episodes());
      std::printf("%s", io::HeldOutReport(*run.holdout).c_str());
    }
    for (std::size_t f = 0; f < folds.size(); ++f) {
      const std::string stage = "fold" + std::to_string(f + 1);
      std::printf("Cross-validation: fold %zu of %zu (%zu runs held out)\n", f + 1, folds.size(),
                  folds[f].size());
      std::fflush(stdout);
      const calibration::RunSubset train = calibration::SelectRuns(
          fit.release, fit.observations, calibration::OtherRuns(fit.release, folds[f]), true);
      const calibration::Objective fold_objective(
          event.scene.scene, train.release, train.observations, file.parameters, objective_options);
      io::FoldRun fold;
      fold.summary = optimise(fold_objective, stage);
      std::printf("%s\n", fold.summary.BriefReport().c_str());
      if (!fold.summary.IsSolutionUsable()) {
        std::cerr << "talus calibrate: fold " << f + 1 << ": " << fold.summary.message
                  << " (no output written)\n";
        return kExitRunFailed;
      }
      fold.scores = calibration::ScoreRuns(
          event.scene.scene,
          calibration::SelectRuns(fit.release, fit.observations, folds[f], false),
          fold_objective.GroundOf(fold.summary.best.u), reference ? &*reference : nullptr,
          args.threads, objective->needs_episodes());
      run.folds.push_back(std::move(fold));
    }
    if (!run.folds.empty()) {
      std::vector<calibration::HeldOutScores> sets;
      for (const io::FoldRun& f : run.folds) sets.push_back(f.scores);
      calibration::HeldOutScores pooled;
      pooled.kinds = calibration::PoolKinds(sets);
      std::printf("Cross-validated (%zu folds), every run scored by the fit without it:\n%s",
                  run.folds.size(), io::HeldOutReport(pooled).c_str());
    }
    run.threads = args.threads;
    run.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

    ThrowIfInterrupted();
    staging.emplace(args.out);
    WriteFileAtomically(staging->path("ground_table.toml"),
                        io::GroundTableToml(file, *objective, fitted));
    WriteFileAtomically(staging->path("ground_table.csv"), io::GroundTableCsv(*objective, fitted));
    WriteFileAtomically(staging->path("history.csv"), io::HistoryCsv(*objective, run.summary));
    std::vector<std::string> outputs = {"ground_table.toml", "ground_table.csv", "history.csv",
                                        "convergence.svg"};
    WriteFileAtomically(staging->path("convergence.svg"), io::ConvergenceSvg(run.summary));
    for (const std::string& kind : objective->kinds()) {
      if (kind == "deposit") continue;
      const std::string name = "observed_vs_simulated_" + kind + ".svg";
      WriteFileAtomically(staging->path(name),
                          io::ObservedSimulatedSvg(kind, before.observations, after.observations));
      outputs.push_back(name);
    }
    outputs.push_back("calibration.json");
    WriteFileAtomically(staging->path("calibration.json"),
                        io::CalibrationJson(file, *objective, run));
    ThrowIfInterrupted();
    staging->Commit(outputs);  // calibration.json last
    // The run is complete: its checkpoint is no longer needed, unless a budget ended a fit
    // (a later --resume with a larger budget goes on from it).
    bool budget = run.summary.termination == calibration::Termination::kMaxEvaluations ||
                  run.summary.termination == calibration::Termination::kMaxTime;
    for (const io::FoldRun& f : run.folds)
      budget = budget || f.summary.termination == calibration::Termination::kMaxEvaluations ||
               f.summary.termination == calibration::Termination::kMaxTime;
    if (!budget) fs::remove(checkpoint_path);
    std::printf("Wrote %zu files to %s in %.1f s%s\n", outputs.size(), args.out.c_str(),
                run.wall_time_s,
                budget ? " (a budget ended a fit: checkpoint.json kept for --resume)" : "");
    return kExitOk;
  } catch (const Interrupted& e) {
    staging.reset();
    std::cerr << "\ntalus calibrate: " << e.what() << "; no output written, " << args.out
              << " is as it was before the run but for " << kCheckpoint
              << " (resume with --resume)\n";
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
  cmd->add_option("--holdout", args->holdout,
                  "Leave runs out of the fit and score them: a number of runs (drawn with the "
                  "optimiser's seed) or a comma-separated list of run ids");
  cmd->add_option("--folds", args->folds,
                  "k-fold cross-validation by run: fit k more times, each without one fold")
      ->check(IntegerRange(2, std::numeric_limits<int>::max()));
  cmd->add_flag("--resume", args->resume,
                "Go on from the checkpoint an interrupted calibration left in --out");
  return [cmd, args]() { return *cmd ? RunCalibrate(*args) : -1; };
}

}  // namespace talus::app
