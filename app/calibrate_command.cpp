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
#include <array>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <functional>
#include <iostream>
#include <limits>
#include <memory>
#include <optional>
#include <sstream>

#include "app/commands.hpp"
#include "app/interrupt.hpp"
#include "app/mpi_session.hpp"
#include "app/simulate.hpp"
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
// Seconds between two writes of the checkpoint during an optimisation.
constexpr double kCheckpointEvery_s = 10;

// Writes the checkpoint on the way out of a failed or interrupted run; a failure to write it is
// reported but does not replace the reason the run ended.
template <class Save>
void SaveBeforeLeaving(const Save& save) {
  try {
    save();
  } catch (const std::exception& e) {
    std::cerr << "talus calibrate: the checkpoint could not be written: " << e.what() << "\n";
  }
}

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

// The processes a calibration runs on: this one alone, or the ranks of an MPI run. Under MPI every
// rank runs the same optimiser; each evaluation's rocks are divided among the ranks and their
// samples joined in rock order on every rank (calibration::EnsembleRunner), so every rank computes
// the same objective, bit for bit, and takes the same steps. Rank 0 alone prints and writes.
struct Processes {
  int rank = 0, size = 1;
  // Agrees on how a step went (every rank calls it at the same steps): the exit code of the first
  // rank that failed, on every rank, with its message printed once. Empty: one process, which
  // prints its own message.
  std::function<int(int code, const std::string& message)> agree;
  calibration::EnsembleRunner runner;                        // empty: the rocks run here
  std::function<std::string(const std::string&)> broadcast;  // rank 0's text on every rank
  bool root() const { return rank == 0; }
  bool mpi() const { return static_cast<bool>(agree); }
  int Step(int code, const std::string& message) const {
    if (agree) return agree(code, message);
    if (code != 0) std::cerr << "talus calibrate: " << message << "\n";
    return code;
  }
};

int RunCalibrate(const CalibrateArgs& args, const Processes& processes) {
  namespace fs = std::filesystem;
  const auto t0 = std::chrono::steady_clock::now();
  const bool root = processes.root();
  io::CalibrationFile file;
  std::unique_ptr<calibration::Objective> objective;
  calibration::ObjectiveOptions objective_options;
  calibration::RunSubset fit;
  std::vector<std::string> holdout;
  std::vector<std::vector<std::string>> folds;
  io::CalibrationCheckpoint checkpoint;
  const std::string checkpoint_path = (fs::path(args.out) / kCheckpoint).string();
  int code = kExitOk;
  std::string message;
  try {
    file = io::LoadCalibration(args.file);
    objective_options = file.objective;
    objective_options.threads = args.threads;
    objective_options.progress = [](long, long) { ThrowIfInterrupted(); };
    objective_options.run_ensemble = processes.runner;
    const io::EventFile& event = file.event;
    if (root) PrintSceneWarnings(event.scene, "calibrate");
    if (root) PrintNotScored(event.not_scored);
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
    code = kExitBadInput;
    message = e.what();
  } catch (const std::exception& e) {
    code = kExitRunFailed;
    message = "cannot load " + args.file + ": " + e.what();
  }
  if (const int failed = processes.Step(code, message)) return failed;
  if (processes.mpi()) {
    // Every rank must run the same calibration as rank 0 (same files, options and splits).
    const std::string identity = "calibration " +
                                 fs::absolute(args.file).lexically_normal().string() +
                                 " (inputs hash " + file.inputs_hash + "), --holdout '" +
                                 args.holdout + "', --folds " + std::to_string(args.folds) +
                                 ", --out " + fs::absolute(args.out).lexically_normal().string();
    if (const std::string of_root = processes.broadcast(identity); of_root != identity) {
      code = kExitBadInput;
      message =
          "started with another calibration than rank 0: " + identity + " instead of " + of_root;
    }
  }
  if (const int failed = processes.Step(code, message)) return failed;
  if (root) {
    message = PrepareOutputDirectory(args.out);
    code = message.empty() ? kExitOk : kExitBadInput;
  }
  if (const int failed = processes.Step(code, message)) return failed;
  const InterruptScope interrupts;
  std::signal(SIGXFSZ, SIG_IGN);
  if (root) RemoveStaleTemporaries(args.out);

  const io::EventFile& event = file.event;
  const ensemble::ReleaseSpec& release = objective->release();
  std::printf(
      "Calibration %s: %d parameters, %zu observations of %ld runs x %ld rocks, %s%s\n"
      "Contact solve: tolerance %g m/s (%s)\n",
      args.file.c_str(), objective->dimension(), fit.observations.size(), release.release_count(),
      release.rocks_per_release, file.optimizer.algorithm.c_str(),
      processes.mpi() ? (", " + std::to_string(processes.size) + " MPI ranks").c_str() : "",
      objective->options().tolerance_m_s, file.tolerance_source.c_str());
  if (!holdout.empty())
    std::printf("Holding out %zu runs: %s\n", holdout.size(), Join(holdout).c_str());
  if (!checkpoint.stages.empty()) std::printf("Resuming from %s\n", checkpoint_path.c_str());
  std::fflush(stdout);
  const bool terminal = ::isatty(STDOUT_FILENO) != 0;
  // The checkpoint holds every evaluation so far; rewriting it after each one would cost time and
  // disk quadratic in the evaluations, so it is written at most every kCheckpointEvery_s, at the
  // end of each optimisation, and when the run is interrupted or fails. A process killed outright
  // loses at most that interval's evaluations, which --resume computes again, identically.
  auto last_save = std::chrono::steady_clock::now();
  const auto save_checkpoint = [&]() {
    if (!root || checkpoint.stages.empty()) return;
    WriteFileAtomically(checkpoint_path, io::CheckpointJson(checkpoint));
    last_save = std::chrono::steady_clock::now();
  };
  // One optimisation, its evaluations replayed from and kept in the checkpoint.
  const auto optimise = [&](const calibration::Objective& target, const std::string& stage) {
    calibration::OptimizerOptions options = file.optimizer;
    options.replay = checkpoint.stages[stage];
    options.on_evaluation = [&, stage](const calibration::Evaluation& e, int index) {
      std::vector<calibration::Evaluation>& kept = checkpoint.stages[stage];
      if (index >= static_cast<int>(kept.size())) {
        kept.push_back(e);
        if (std::chrono::steady_clock::now() - last_save >
            std::chrono::duration<double>(kCheckpointEvery_s))
          save_checkpoint();
      }
      // Under MPI the ranks stop together, inside an evaluation (the runner agrees on it).
      if (!processes.mpi()) ThrowIfInterrupted();
      std::printf("%s  %s evaluation %4d  objective %-12.6g %s%s", terminal ? "\r" : "",
                  stage.c_str(), index, e.value, e.feasible ? "" : "(infeasible)",
                  terminal ? "   " : "\n");
      std::fflush(stdout);
    };
    calibration::OptimizerSummary summary = calibration::Optimize(target, options);
    save_checkpoint();
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
    run.not_scored = event.not_scored;
    run.summary = optimise(*objective, "fit");
    std::printf("%s", run.summary.FullReport().c_str());
    if (!run.summary.IsSolutionUsable()) throw std::runtime_error(run.summary.message);
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
      if (file.bootstrap_options.resamples > 0) {
        calibration::BootstrapOptions bootstrap = file.bootstrap_options;
        bootstrap.resolution = file.bootstrap_resolution.value_or(options.fd_step);
        bootstrap.profiles = run.profiles;
        std::printf("Bootstrap over runs: %d resamples, each refitted...\n", bootstrap.resamples);
        std::fflush(stdout);
        run.bootstrap =
            calibration::BootstrapOverRuns(*objective, best.u, bootstrap, run.summary.history);
        std::printf("%s", run.bootstrap->Report().c_str());
        if (file.seed_options.seeds > 0) {
          std::printf("Refits with %d other release seeds...\n", file.seed_options.seeds);
          std::fflush(stdout);
          run.seeds = calibration::RefitWithOtherSeeds(*objective, *run.bootstrap, bootstrap,
                                                       file.seed_options);
          std::printf("%s", run.seeds->Report().c_str());
        }
      }
    }
    const GroundTable fitted = objective->GroundOf(best.u);
    // The fitted runs scored before and after, for the observed-vs-simulated plots. Every scoring
    // runs the scene as the objective does (its contact-solve tolerance).
    std::printf("Scoring the observations before and after for the plots...\n");
    std::fflush(stdout);
    const calibration::HeldOutScores before = calibration::ScoreRuns(
        objective->scene(), fit, objective->GroundOf(run.summary.initial.u), nullptr, args.threads,
        objective->needs_episodes(), processes.runner);
    const calibration::HeldOutScores after =
        calibration::ScoreRuns(objective->scene(), fit, fitted, nullptr, args.threads,
                               objective->needs_episodes(), processes.runner);
    if (!holdout.empty()) {
      std::printf("Scoring the %zu held-out runs...\n", holdout.size());
      std::fflush(stdout);
      run.holdout = calibration::ScoreRuns(
          objective->scene(),
          calibration::SelectRuns(event.scene.release, event.observations, holdout, false), fitted,
          reference ? &*reference : nullptr, args.threads, objective->needs_episodes(),
          processes.runner);
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
      if (!fold.summary.IsSolutionUsable())
        throw std::runtime_error("fold " + std::to_string(f + 1) + ": " + fold.summary.message);
      fold.scores = calibration::ScoreRuns(
          objective->scene(),
          calibration::SelectRuns(fit.release, fit.observations, folds[f], false),
          fold_objective.GroundOf(fold.summary.best.u), reference ? &*reference : nullptr,
          args.threads, objective->needs_episodes(), processes.runner);
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

    // Rank 0 writes; the other ranks only agree on how it went (below).
    if (root) {
      ThrowIfInterrupted();
      staging.emplace(args.out);
      WriteFileAtomically(staging->path("ground_table.toml"),
                          io::GroundTableToml(file, *objective, fitted));
      WriteFileAtomically(staging->path("ground_table.csv"),
                          io::GroundTableCsv(*objective, fitted));
      WriteFileAtomically(staging->path("history.csv"), io::HistoryCsv(*objective, run.summary));
      std::vector<std::string> outputs = {"ground_table.toml", "ground_table.csv", "history.csv",
                                          "convergence.svg"};
      WriteFileAtomically(staging->path("convergence.svg"), io::ConvergenceSvg(run.summary));
      for (const std::string& kind : objective->kinds()) {
        if (kind == "deposit") continue;
        const std::string name = "observed_vs_simulated_" + kind + ".svg";
        WriteFileAtomically(staging->path(name), io::ObservedSimulatedSvg(kind, before.observations,
                                                                          after.observations));
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
    }
  } catch (const Interrupted& e) {
    staging.reset();
    SaveBeforeLeaving(save_checkpoint);
    code = ExitCodeForSignal(e.signal());
    message = std::string(e.what()) + "; no output written, " + args.out +
              " is as it was before the run but for " + kCheckpoint + " (resume with --resume)";
    if (root) std::printf("\n");
  } catch (const std::exception& e) {
    code = kExitRunFailed;
    message =
        (staging ? staging->Describe(e.what()) : std::string(e.what())) + " (no output written)";
    staging.reset();
    SaveBeforeLeaving(save_checkpoint);
  }
  return processes.Step(code, message);
}

#if TALUS_HAVE_MPI

// Counts of an ensemble report as bytes, and back.
std::string CountsBytes(const ensemble::EnsembleReport& r) {
  const std::array<long, 9> counts = {
      r.rocks,  r.by_end[0],         r.by_end[1], r.by_end[2],        r.by_end[3],
      r.raised, r.stayed_at_release, r.steps,     r.unconverged_steps};
  return std::string(reinterpret_cast<const char*>(counts.data()), sizeof counts);
}
ensemble::EnsembleReport ReportOfCounts(const std::string& bytes) {
  std::array<long, 9> c{};
  std::memcpy(c.data(), bytes.data(), sizeof c);
  ensemble::EnsembleReport r;
  r.rocks = c[0];
  r.by_end = {c[1], c[2], c[3], c[4]};
  r.raised = c[5];
  r.stayed_at_release = c[6];
  r.steps = c[7];
  r.unconverged_steps = c[8];
  return r;
}

// An evaluation's rocks divided among the ranks: rank r runs [r N / R, (r + 1) N / R) with its
// threads, and every rank receives every rank's samples, joined in rock order. The ranks agree on
// failures inside: an interrupt or an error on any rank is thrown on every rank.
calibration::EnsembleRunner RanksRunner(const MpiSession& mpi) {
  return [&mpi](const Scene& scene, const ensemble::ReleaseSpec& release,
                const ensemble::EnsembleOptions& options, fieldobs::EnsembleSamples* samples) {
    const long total = release.total_rocks();
    ensemble::EnsembleOptions mine = options;
    mine.first_rock = total * mpi.rank() / mpi.size();
    mine.end_rock = total * (mpi.rank() + 1) / mpi.size();
    std::string payload;
    ensemble::EnsembleReport report;
    try {
      fieldobs::EnsembleSamples part(release);
      report = ensemble::RunEnsemble(scene, release, mine, &part);
      payload = "0" + CountsBytes(report) + part.Serialize();
    } catch (const Interrupted& e) {
      payload = "I" + std::to_string(e.signal());
    } catch (const std::exception& e) {
      payload = std::string("E") + e.what();
    }
    const std::vector<std::string> parts = AllGatherText(mpi, payload);
    for (const std::string& p : parts)
      if (p[0] == 'I') throw Interrupted(std::stoi(p.substr(1)));
    for (std::size_t r = 0; r < parts.size(); ++r)
      if (parts[r][0] == 'E')
        throw std::runtime_error("rank " + std::to_string(r) + ": " + parts[r].substr(1));
    ensemble::EnsembleReport all;
    const std::size_t counts = CountsBytes(all).size();
    for (const std::string& p : parts) {
      all.AddCounts(ReportOfCounts(p.substr(1, counts)));
      samples->Append(p.substr(1 + counts));
    }
    all.threads = report.threads;
    all.wall_time_s = report.wall_time_s;
    return all;
  };
}

#endif

// One process, or every rank of an MPI launch (mpirun / srun).
int RunCalibrateOnProcesses(const CalibrateArgs& args) {
  if (LaunchedRanks() <= 1) return RunCalibrate(args, Processes{});
#if !TALUS_HAVE_MPI
  const char* rank = std::getenv("OMPI_COMM_WORLD_RANK");
  if (!rank || std::atoi(rank) == 0)
    std::cerr << "talus calibrate: started as " << LaunchedRanks()
              << " MPI processes, but this talus was built without MPI (configure with "
                 "-DTALUS_WITH_MPI=ON, or run one process)\n";
  return kExitBadInput;
#else
  const MpiSession mpi;
  Processes processes;
  processes.rank = mpi.rank();
  processes.size = mpi.size();
  processes.agree = [&mpi](int code, const std::string& message) {
    return Agree(mpi, code, message, "talus calibrate");
  };
  processes.runner = RanksRunner(mpi);
  processes.broadcast = [&mpi](const std::string& text) { return BroadcastText(mpi, text); };
  // Rank 0 tells the story; the others would tell it again.
  if (mpi.rank() != 0 && !std::freopen("/dev/null", "w", stdout))
    std::cerr << "talus calibrate: rank " << mpi.rank() << " cannot silence its output\n";
  try {
    return RunCalibrate(args, processes);
  } catch (const Interrupted& e) {
    // A signal while this rank waited for the others outside a run (mpirun ends every rank when
    // one dies): unwinding to here removed this rank's temporary files.
    std::cerr << "talus calibrate: rank " << mpi.rank() << ": " << e.what()
              << " while waiting for the other ranks\n";
    return ExitCodeForSignal(e.signal());
  }
#endif
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
  return [cmd, args]() { return *cmd ? RunCalibrateOnProcesses(*args) : -1; };
}

}  // namespace talus::app
