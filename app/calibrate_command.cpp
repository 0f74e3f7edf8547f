// talus calibrate: fit ground parameters to an event's observations (docs/calibration.md). The
// calibration itself is one library call (calibration::Calibrate, calibration/calibrate.hpp); this
// verb loads and checks the calibration file, its event, scene and observations before any rock
// runs, divides the rocks among MPI ranks, prints the run's progress, keeps DIR/checkpoint.json
// (every evaluation as it comes, so that an interrupted calibration resumes (--resume) to the
// result an uninterrupted one gives) and writes the fitted ground table, calibration.json,
// history.csv, the plots and report.html, all complete or none.

#include <unistd.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <functional>
#include <iostream>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <sstream>

#include "app/commands.hpp"
#include "app/console.hpp"
#include "app/interrupt.hpp"
#include "app/mpi_session.hpp"
#include "app/run_verb.hpp"
#include "app/simulate.hpp"
#include "calibration/calibrate.hpp"
#include "common/atomic_file.hpp"
#include "common/error.hpp"
#include "io/calibration_checkpoint.hpp"
#include "io/calibration_file.hpp"
#include "io/calibration_outputs.hpp"
#include "io/calibration_plots.hpp"
#include "io/calibration_report_html.hpp"
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

// The phase a calibration is in, for its status line on a terminal: an optimisation's stage ("fit",
// "fold1") or a phase it announced ("Measuring the roughness and the profiles at the optimum").
struct CalibrationPhase {
  std::string phase = "starting";
  std::string last;   // the optimisation's last evaluation, as its status line said it
  int evaluated = 0;  // ensembles run in this phase
  void Begin(const std::string& name) {
    phase = name;
    last.clear();
    evaluated = 0;
  }
  // The rocks of the ensemble running now (the objective's progress).
  void Rocks(long done, long total) {
    if (total <= 0 || !ShowsProgress()) return;
    Status((last.empty() ? "  " + phase + ": evaluation " + std::to_string(evaluated + 1) : last) +
           "  [rocks " + std::to_string(done) + "/" + std::to_string(total) + "]");
    if (done == total) ++evaluated;
  }
};
CalibrationPhase& CalibrationStatus() {
  static CalibrationPhase phase;
  return phase;
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
    if (code != 0) Fail("calibrate", message);
    return code;
  }
};

// The calibration as loaded and checked, and the checkpoint it goes on from.
struct Loaded {
  io::CalibrationFile file;
  std::unique_ptr<calibration::CalibrationProblem> problem;
  io::CalibrationCheckpoint checkpoint;
  std::string checkpoint_path;
};

// The shape of every evaluation of each optimisation of the calibration: the fit's, each fold's.
std::map<std::string, io::EvaluationShape> EvaluationShapes(
    const calibration::CalibrationProblem& problem, int folds) {
  const auto shape = [](const calibration::Objective& o) {
    return io::EvaluationShape{o.dimension(), static_cast<int>(o.kinds().size()),
                               o.residual_count()};
  };
  std::map<std::string, io::EvaluationShape> shapes = {{"fit", shape(problem.objective())}};
  for (int f = 0; f < folds; ++f)
    shapes["fold" + std::to_string(f + 1)] = shape(problem.ObjectiveOn(problem.FoldTraining(f)));
  return shapes;
}

// Loads the calibration file, its event, scene and observations, splits the runs (--holdout,
// --folds) and checks the checkpoint in --out against --resume. kExitOk, or the exit code with the
// reason in *message.
int Load(const CalibrateArgs& args, const Processes& processes, Loaded* loaded,
         std::string* message) {
  namespace fs = std::filesystem;
  loaded->checkpoint_path = (fs::path(args.out) / kCheckpoint).string();
  try {
    io::CalibrationFile& file = loaded->file;
    file = io::LoadCalibration(args.file);
    calibration::ObjectiveOptions objective = file.objective;
    objective.threads = args.threads;
    objective.progress = [root = processes.root()](long done, long total) {
      ThrowIfInterrupted();
      if (root) CalibrationStatus().Rocks(done, total);
    };
    objective.run_ensemble = processes.runner;
    const io::EventFile& event = file.event;
    if (processes.root()) PrintSceneWarnings(event.scene, "calibrate");
    if (processes.root()) PrintNotScored(event.not_scored);
    loaded->problem = io::MakeCalibrationProblem(file, args.holdout, args.folds, objective);
    io::CalibrationCheckpoint& checkpoint = loaded->checkpoint;
    checkpoint.path_hash = file.path_hash;
    checkpoint.holdout = loaded->problem->holdout();
    checkpoint.folds = args.folds;
    const std::string& path = loaded->checkpoint_path;
    const bool exists = fs::exists(path);
    if (args.resume) {
      if (!exists) throw InputError("--resume: no " + path + " to resume from");
      const io::CalibrationCheckpoint saved = io::ReadCheckpoint(path);
      if (saved.path_hash != checkpoint.path_hash || saved.holdout != checkpoint.holdout ||
          saved.folds != args.folds)
        throw InputError(path +
                         ": the checkpoint belongs to another calibration (other inputs, "
                         "parameters, optimiser options, --holdout or --folds)");
      io::CheckEvaluations(saved, path, EvaluationShapes(*loaded->problem, args.folds));
      checkpoint.stages = saved.stages;
    } else if (exists) {
      // One that cannot be resumed (an older talus's, damaged) says so now, not after --resume.
      io::ReadCheckpoint(path);
      throw InputError(path +
                       " holds the evaluations of an unfinished calibration: resume it with "
                       "--resume, or remove it");
    }
  } catch (const InputError& e) {
    *message = e.what();
    return kExitBadInput;
  } catch (const std::exception& e) {
    *message = "cannot load " + args.file + ": " + e.what();
    return kExitRunFailed;
  }
  return kExitOk;
}

// Under MPI, every rank must run the same calibration as rank 0 (same files, options and splits).
int AgreeOnTheCalibration(const CalibrateArgs& args, const Loaded& loaded,
                          const Processes& processes, std::string* message) {
  namespace fs = std::filesystem;
  if (!processes.mpi()) return kExitOk;
  const std::string identity =
      "calibration " + fs::absolute(args.file).lexically_normal().string() + " (inputs hash " +
      loaded.file.inputs_hash + "), --holdout '" + args.holdout + "', --folds " +
      std::to_string(args.folds) + ", --out " + fs::absolute(args.out).lexically_normal().string();
  if (const std::string of_root = processes.broadcast(identity); of_root != identity) {
    *message =
        "started with another calibration than rank 0: " + identity + " instead of " + of_root;
    return kExitBadInput;
  }
  return kExitOk;
}

void PrintHeader(const CalibrateArgs& args, const Loaded& loaded, const Processes& processes) {
  const calibration::Objective& objective = loaded.problem->objective();
  const ensemble::ReleaseSpec& release = objective.release();
  const std::vector<std::string>& holdout = loaded.problem->holdout();
  Say("Calibration %s: %d parameters, %zu observations of %ld runs x %ld rocks, %s%s\n"
      "Contact solve: tolerance %g m/s (%s)\n",
      args.file.c_str(), objective.dimension(), loaded.problem->fitted_runs().observations.size(),
      release.release_count(), release.rocks_per_release,
      loaded.file.options.optimizer.algorithm.c_str(),
      processes.mpi() ? (", " + std::to_string(processes.size) + " MPI ranks").c_str() : "",
      objective.options().tolerance_m_s, loaded.file.tolerance_source.c_str());
  if (!holdout.empty()) Say("Holding out %zu runs: %s\n", holdout.size(), Join(holdout).c_str());
  if (!loaded.checkpoint.stages.empty()) Say("Resuming from %s\n", loaded.checkpoint_path.c_str());
}

// The checkpoint holds every evaluation so far; rewriting it after each one would cost time and
// disk quadratic in the evaluations, so it is written at most every kCheckpointEvery_s, at the
// end of each optimisation, and when the run is interrupted or fails. A process killed outright
// loses at most that interval's evaluations, which --resume computes again, identically. Only
// rank 0 writes it.
class CheckpointKeeper {
 public:
  CheckpointKeeper(Loaded& loaded, bool root) : loaded_(loaded), root_(root) {}

  // An optimisation begins: it is in the checkpoint from now on, if only with no evaluation.
  void Begin(const std::string& stage) { loaded_.checkpoint.stages[stage]; }
  // Keeps a new evaluation (a replayed one is there already); writes when the interval is over.
  void Keep(const std::string& stage, const calibration::Evaluation& e, int index) {
    std::vector<calibration::Evaluation>& kept = loaded_.checkpoint.stages[stage];
    if (index < static_cast<int>(kept.size())) return;
    kept.push_back(e);
    if (std::chrono::steady_clock::now() - last_save_ >
        std::chrono::duration<double>(kCheckpointEvery_s))
      Save();
  }
  void Save() {
    if (!root_ || loaded_.checkpoint.stages.empty()) return;
    WriteFileAtomically(loaded_.checkpoint_path, io::CheckpointJson(loaded_.checkpoint));
    last_save_ = std::chrono::steady_clock::now();
  }
  // On the way out of a failed or interrupted run: a failure to write is reported but does not
  // replace the reason the run ended.
  void SaveBeforeLeaving() {
    try {
      Save();
    } catch (const std::exception& e) {
      Fail("calibrate", std::string("the checkpoint could not be written: ") + e.what());
    }
  }

 private:
  Loaded& loaded_;
  bool root_;
  std::chrono::steady_clock::time_point last_save_ = std::chrono::steady_clock::now();
};

// The library's options with this run's callbacks: the checkpoint, interrupts and printing.
calibration::CalibrationOptions RunOptions(const Loaded& loaded, const Processes& processes,
                                           CheckpointKeeper& keeper) {
  calibration::CalibrationOptions options = loaded.file.options;
  options.replay = loaded.checkpoint.stages;
  // On a terminal, one status line: the optimisation's last evaluation, or the phase and how far
  // its current evaluation's rocks are (CalibrationStatus); elsewhere a line per evaluation.
  const bool terminal = ShowsProgress() && processes.root();
  options.on_optimization_begins = [&keeper](const std::string& stage) {
    keeper.Begin(stage);
    CalibrationStatus().Begin(stage);
  };
  options.on_evaluation = [&keeper, &processes, terminal](const std::string& stage,
                                                          const calibration::Evaluation& e,
                                                          int index) {
    keeper.Keep(stage, e, index);
    // Under MPI the ranks stop together, inside an evaluation (the runner agrees on it).
    if (!processes.mpi()) ThrowIfInterrupted();
    char line[160];
    std::snprintf(line, sizeof line, "  %s evaluation %4d  objective %-12.6g %s", stage.c_str(),
                  index, e.value, e.feasible ? "" : "(infeasible)");
    CalibrationStatus().last = line;
    if (terminal)
      Status(line);
    else
      Say("%s\n", line);
  };
  options.on_optimization_ends = [&keeper](const std::string&) {
    keeper.Save();
    CalibrationStatus().last.clear();
    EndStatus();
  };
  options.on_progress = [](const std::string& text) {
    Say("%s", text.c_str());
    // "Measuring the roughness and the profiles at the optimum...": the phase now running.
    if (const auto dots = text.find("..."); dots != std::string::npos)
      CalibrationStatus().Begin(text.substr(0, dots));
  };
  return options;
}

// Writes the outputs into --out through `staging`, calibration.json last; removes the checkpoint
// unless a budget ended a fit (a later --resume with a larger budget goes on from it).
void WriteOutputs(const CalibrateArgs& args, const Loaded& loaded,
                  const calibration::CalibrationSummary& run,
                  std::optional<StagingDirectory>& staging) {
  const io::CalibrationFile& file = loaded.file;
  const calibration::Objective& objective = loaded.problem->objective();
  ThrowIfInterrupted();
  staging.emplace(args.out);
  WriteFileAtomically(staging->path("ground_table.toml"),
                      io::GroundTableToml(file, objective, run.fitted, &run));
  WriteFileAtomically(staging->path("ground_table.csv"), io::GroundTableCsv(objective, run.fitted));
  WriteFileAtomically(staging->path("history.csv"), io::HistoryCsv(objective, run.fit));
  std::vector<std::string> outputs = {"ground_table.toml", "ground_table.csv", "history.csv",
                                      "convergence.svg"};
  if (objective.parameters().has_shapes()) {
    WriteFileAtomically(staging->path("shape_table.toml"),
                        io::ShapeTableToml(file, objective, run));
    outputs.push_back("shape_table.toml");
  }
  io::CalibrationReportInput report;
  report.convergence_svg = io::ConvergenceSvg(run.fit);
  WriteFileAtomically(staging->path("convergence.svg"), report.convergence_svg);
  for (const std::string& kind : objective.kinds()) {
    if (kind == "deposit") continue;
    const std::string name = "observed_vs_simulated_" + kind + ".svg";
    report.observed_simulated.push_back(
        io::ObservedSimulatedSvg(kind, run.before.observations, run.after.observations));
    WriteFileAtomically(staging->path(name), report.observed_simulated.back());
    outputs.push_back(name);
  }
  report.calibration_json = io::CalibrationJson(file, objective, run, kVersion);
  WriteFileAtomically(staging->path("report.html"), io::CalibrationReportHtml(report));
  outputs.push_back("report.html");
  outputs.push_back("calibration.json");
  WriteFileAtomically(staging->path("calibration.json"), report.calibration_json);
  ThrowIfInterrupted();
  staging->Commit(outputs);  // calibration.json last
  const bool budget = run.BudgetEndedAFit();
  if (!budget) std::filesystem::remove(loaded.checkpoint_path);
  Say("Wrote %zu files to %s in %.1f s%s\n", outputs.size(), args.out.c_str(), run.wall_time_s,
      budget ? " (a budget ended a fit: checkpoint.json kept for --resume)" : "");
  for (const std::string& warning : calibration::CalibrationWarnings(run, objective))
    Warn("calibrate", warning);
}

int RunCalibrate(const CalibrateArgs& args, const Processes& processes) {
  const bool root = processes.root();
  Loaded loaded;
  std::string message;
  int code = Load(args, processes, &loaded, &message);
  if (const int failed = processes.Step(code, message)) return failed;
  code = AgreeOnTheCalibration(args, loaded, processes, &message);
  if (const int failed = processes.Step(code, message)) return failed;
  if (root) {
    message = PrepareOutputDirectory(args.out);
    code = message.empty() ? kExitOk : kExitBadInput;
  }
  if (const int failed = processes.Step(code, message)) return failed;
  const InterruptScope interrupts;
  if (root) {
    RemoveStaleTemporaries(args.out);
    SetRunLogDirectory(args.out);
  }
  PrintHeader(args, loaded, processes);

  CheckpointKeeper keeper(loaded, root);
  std::optional<StagingDirectory> staging;
  VerbHooks hooks;
  hooks.on_failure = [&](bool interrupted) {
    keeper.SaveBeforeLeaving();
    if (interrupted && root) EndStatus();
  };
  hooks.interrupted_message = [&](const Interrupted& e) {
    return std::string(e.what()) + "; no output written, " + args.out +
           " is as it was before the run but for " + kCheckpoint + " (resume with --resume)";
  };
  const VerbOutcome outcome = RunStaged(
      args.out, staging,
      [&] {
        const calibration::CalibrationSummary run =
            calibration::Calibrate(*loaded.problem, RunOptions(loaded, processes, keeper));
        // Rank 0 writes; the other ranks only agree on how it went (below).
        if (root) WriteOutputs(args, loaded, run, staging);
      },
      hooks);
  return processes.Step(outcome.code, outcome.message);
}

#if TALUS_HAVE_MPI

// Counts of an ensemble report as bytes, and back.
std::string CountsBytes(const ensemble::EnsembleReport& r) {
  const std::array<long, 10> counts = {
      r.rocks,     r.by_end[0], r.by_end[1],         r.by_end[2], r.by_end[3],
      r.by_end[4], r.raised,    r.stayed_at_release, r.steps,     r.unconverged_steps};
  return std::string(reinterpret_cast<const char*>(counts.data()), sizeof counts);
}
ensemble::EnsembleReport ReportOfCounts(const std::string& bytes) {
  std::array<long, 10> c{};
  std::memcpy(c.data(), bytes.data(), sizeof c);
  ensemble::EnsembleReport r;
  r.rocks = c[0];
  r.by_end = {c[1], c[2], c[3], c[4], c[5]};
  r.raised = c[6];
  r.stayed_at_release = c[7];
  r.steps = c[8];
  r.unconverged_steps = c[9];
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
  if (LaunchedRank() == 0)
    Fail("calibrate", "started as " + std::to_string(LaunchedRanks()) +
                          " MPI processes, but this talus was built without MPI (configure with "
                          "-DTALUS_WITH_MPI=ON, or run one process)");
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
    Fail("calibrate", "rank " + std::to_string(mpi.rank()) + " cannot silence its output");
  try {
    return RunCalibrate(args, processes);
  } catch (const Interrupted& e) {
    // A signal while this rank waited for the others outside a run (mpirun ends every rank when
    // one dies): unwinding to here removed this rank's temporary files.
    Fail("calibrate", "rank " + std::to_string(mpi.rank()) + ": " + e.what() +
                          " while waiting for the other ranks");
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
