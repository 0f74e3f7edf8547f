#pragma once
// talus simulate, shared by its one-process run (simulate_command.cpp) and its MPI run
// (simulate_mpi.cpp): the command-line arguments, loading and checking them, the messages.

#include <chrono>
#include <optional>
#include <string>
#include <utility>

#include "app/console.hpp"
#include "app/ensemble_args.hpp"
#include "ensemble/runner.hpp"
#include "io/scene_file.hpp"

namespace talus::app {

struct SimulateArgs {
  std::string scene;
  std::string out;
  EnsembleArgs ensemble;   // --rocks (per release), --threads, --seed
  std::string rock_range;  // "A:B": write a partial result of rocks A .. B - 1
  std::string preset;      // --preset: fast, default, accurate; empty: the scene's
  // --self-check N: rerun N rocks at dt/2 and compare; 0: none (over the scene's [solver]
  // self_check); -1: not given (the scene's).
  long self_check = -1;
};

// Loads the scene with the overrides of `args` and the rocks to run ([0, total), or --rock-range).
// Returns kExitOk, or the exit code with the reason in *message (bad input: kExitBadInput).
int LoadForSimulate(const SimulateArgs& args, io::SceneFile* scene, std::pair<long, long>* range,
                    std::string* message);

// "rock <shape> (<mass> kg, <n> hull vertices); <k> releases x <n> rocks, seed <s>", or the runs
// and blocks of a run table.
std::string DescribeRocks(const io::SceneFile& scene);

// Prints the scene's warnings (io::SceneFile::warnings) on stderr, one "talus <command>: WARNING:"
// line each.
void PrintSceneWarnings(const io::SceneFile& scene, const char* command = "simulate");
// Prints what the run's endings censor (ensemble::RunWarnings) on stderr, one
// "talus <command>: WARNING:" line each.
void PrintRunWarnings(const ensemble::EnsembleReport& report, const io::SceneFile& scene,
                      const char* command = "simulate");
// Prints each observed value an event holds but does not score (io::EventFile::not_scored).
void PrintNotScored(const std::vector<std::string>& not_scored);

// How many processes an MPI launcher (mpirun, srun) started this one among; 1 without a launcher.
int LaunchedRanks();
// This process's rank as the launcher states it (Open MPI, PMI, PMIx); 0 when none does.
int LaunchedRank();

// talus simulate across the ranks of an MPI run: the rocks are divided among the ranks, each
// writes a part (io/partial.hpp) and rank 0 merges them into --out, byte for byte the outputs of
// one process. Only rank 0 prints and writes --out; every rank returns the same exit code.
int RunSimulateOnRanks(const SimulateArgs& args);

// "rocks done / total, rate, time left" as the status line on a terminal (console.hpp); nothing
// otherwise or with --quiet.
class ProgressBar {
 public:
  ProgressBar() : enabled_(ShowsProgress()), start_(std::chrono::steady_clock::now()) {}
  void operator()(long done, long total) {
    if (!enabled_ || total <= 0) return;
    const double elapsed =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    Status(ProgressLine("", double(done), double(total), "rocks", 0, elapsed));
    if (done == total) EndStatus();
  }
  // Ends a bar left unfinished, so that a message starts on a line of its own.
  void Break() { EndStatus(); }

 private:
  bool enabled_;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace talus::app
