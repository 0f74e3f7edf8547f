#pragma once
// Each verb of the talus program lives in its own file and registers itself on the CLI11 app.
// Add<Verb>Command adds the subcommand and returns a function that runs it when it was chosen.

#include <CLI/CLI.hpp>
#include <functional>
#include <string>

namespace talus::app {

using Runner = std::function<int()>;

Runner AddDemoCommand(CLI::App& app);
Runner AddRockCommand(CLI::App& app);
Runner AddSimulateCommand(CLI::App& app);
Runner AddValidateCommand(CLI::App& app);
Runner AddCalibrateCommand(CLI::App& app);
Runner AddMergeCommand(CLI::App& app);

// Exit codes, the same for every verb (README.md, "Exit codes").
constexpr int kExitOk = 0;
constexpr int kExitRunFailed = 1;  // the input was good but the run failed (e.g. a disk full)
constexpr int kExitBadInput = 2;   // bad input or usage, reported before any work
// Interrupted by a signal: 128 + the signal (130 for SIGINT, 143 for SIGTERM), as shells do.
constexpr int ExitCodeForSignal(int signal) { return 128 + signal; }

// A validator for integer options: a whole number from `min` to `max`, else the message
// "must be >= min" (or "<= max", or "must be an integer") with the value given.
CLI::Validator IntegerRange(long long min, long long max);

// The most worker threads a run may ask for: kThreadsPerCore per core of this machine, at least
// kMinMaxThreads. Threads beyond the cores only add memory (a raster footprint grid and finished
// rocks waiting to be written per thread) and no speed.
constexpr int kThreadsPerCore = 4;
constexpr int kMinMaxThreads = 16;
int MaxThreads();

// A validator for --threads: 0 (one per core) to MaxThreads(), else a message naming the bound and
// the machine's cores.
CLI::Validator ThreadCount();

// Creates the output directory `dir` (with its parents) and checks that it can be written; on
// failure the reason ("--out <dir> exists and is not a directory", ...), else "".
std::string PrepareOutputDirectory(const std::string& dir);

}  // namespace talus::app
