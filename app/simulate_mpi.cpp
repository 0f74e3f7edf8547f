// talus simulate under mpirun / srun: the rocks are divided among the ranks in contiguous ranges,
// each rank runs its range with its threads into a part (io/partial.hpp) in a private staging
// directory, sends the part's files to rank 0, and rank 0 merges the parts into --out with the
// code of `talus merge`. The ranks agree on success at every step (loading, running, sending), so
// that a failure on any rank ends every rank with one message from rank 0 and no output.

#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "app/commands.hpp"
#include "app/console.hpp"
#include "app/interrupt.hpp"
#include "app/mpi_session.hpp"
#include "app/run_outputs.hpp"
#include "app/run_verb.hpp"
#include "app/simulate.hpp"
#include "common/error.hpp"

#if TALUS_HAVE_MPI
#include <mpi.h>
#endif

namespace talus::app {

int LaunchedRanks() {
  // Open MPI's mpirun; launchers speaking PMI (MPICH's, srun --mpi=pmi2); srun with PMIx.
  const char* size = std::getenv("OMPI_COMM_WORLD_SIZE");
  if (!size) size = std::getenv("PMI_SIZE");
  if (!size && std::getenv("PMIX_RANK")) size = std::getenv("SLURM_STEP_NUM_TASKS");
  const int n = size ? std::atoi(size) : 1;
  return n > 1 ? n : 1;
}

int LaunchedRank() {
  for (const char* name : {"OMPI_COMM_WORLD_RANK", "PMI_RANK", "PMIX_RANK"})
    if (const char* rank = std::getenv(name)) return std::atoi(rank);
  return 0;
}

#if !TALUS_HAVE_MPI

int RunSimulateOnRanks(const SimulateArgs&) {
  if (LaunchedRank() == 0)
    std::cerr << "talus simulate: started as " << LaunchedRanks()
              << " MPI processes, but this talus was built without MPI (configure with "
                 "-DTALUS_WITH_MPI=ON, or run one process)\n";
  return kExitBadInput;
}

#else

namespace {

namespace fs = std::filesystem;

constexpr std::size_t kChunk = std::size_t{1} << 26;  // bytes per message (64 MiB)

// Sends the files of a part directory to rank 0.
void SendPart(const fs::path& dir) {
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(dir))
    if (entry.is_regular_file()) files.push_back(entry.path());
  int count = static_cast<int>(files.size());
  Send(&count, 1, MPI_INT);
  std::vector<char> buffer(kChunk);
  for (const fs::path& file : files) {
    const std::string name = file.filename().string();
    int length = static_cast<int>(name.size());
    Send(&length, 1, MPI_INT);
    Send(name.data(), length, MPI_CHAR);
    std::uint64_t size = fs::file_size(file);
    Send(&size, 1, MPI_UINT64_T);
    std::ifstream in(file, std::ios::binary);
    // A read that fails sends zeros of the right length; rank 0 is told below and merges nothing.
    bool ok = static_cast<bool>(in);
    for (std::uint64_t sent = 0; sent < size;) {
      const auto n = static_cast<std::size_t>(std::min<std::uint64_t>(kChunk, size - sent));
      if (ok && !in.read(buffer.data(), static_cast<std::streamsize>(n))) ok = false;
      Send(buffer.data(), static_cast<int>(n), MPI_BYTE);
      sent += n;
    }
    int status = ok ? 0 : 1;
    Send(&status, 1, MPI_INT);
  }
}

// Receives the part of rank `from` into `dir`. Keeps receiving after a failure (so that the
// sender is never left waiting) and then reports the first one.
void ReceivePart(int from, const fs::path& dir) {
  std::string error;
  std::error_code ignored;
  fs::create_directories(dir, ignored);
  int count = 0;
  Receive(&count, 1, MPI_INT, from);
  std::vector<char> buffer(kChunk);
  for (int k = 0; k < count; ++k) {
    int length = 0;
    Receive(&length, 1, MPI_INT, from);
    std::string name(static_cast<std::size_t>(length), '\0');
    Receive(name.data(), length, MPI_CHAR, from);
    std::uint64_t size = 0;
    Receive(&size, 1, MPI_UINT64_T, from);
    const fs::path path = dir / name;
    std::ofstream out(path, std::ios::binary);
    for (std::uint64_t received = 0; received < size;) {
      const auto n = static_cast<std::size_t>(std::min<std::uint64_t>(kChunk, size - received));
      Receive(buffer.data(), static_cast<int>(n), MPI_BYTE, from);
      out.write(buffer.data(), static_cast<std::streamsize>(n));
      received += n;
    }
    out.close();
    int status = 0;
    Receive(&status, 1, MPI_INT, from);
    if (error.empty() && status != 0)
      error = "rank " + std::to_string(from) + " could not read its " + name;
    if (error.empty() && !out) error = "cannot write " + path.string();
  }
  if (!error.empty()) throw std::runtime_error(error);
}

// What must be the same on every rank: the ensemble (scene inputs, seed, rocks) and the options.
std::string EnsembleIdentity(const SimulateArgs& args, const io::SceneFile& scene) {
  return "scene " + fs::absolute(args.scene).lexically_normal().string() + " (inputs hash " +
         scene.inputs_hash + "), seed " + std::to_string(scene.release.seed) + ", " +
         std::to_string(scene.release.total_rocks()) + " rocks, solver preset " +
         ToString(scene.solver_preset) + ", --out " +
         fs::absolute(args.out).lexically_normal().string();
}

int SimulateOnRanks(const MpiSession& mpi, const SimulateArgs& args) {
  const auto t0 = std::chrono::steady_clock::now();
  const bool root = mpi.rank() == 0;

  // Loading: every rank reads the scene and must find the same ensemble as rank 0.
  io::SceneFile scene;
  std::pair<long, long> range;
  std::string message;
  int code = LoadForSimulate(args, &scene, &range, &message);
  if (code == kExitOk && !args.rock_range.empty()) {
    code = kExitBadInput;
    message =
        "--rock-range is for runs of one process (e.g. a job array); under mpirun the ranks "
        "share all rocks";
  }
  if (code == kExitOk && scene.self_check > 0) {
    code = kExitBadInput;
    message =
        "--self-check and [solver] self_check are for runs of one process; under mpirun, check "
        "the step on one process first (talus simulate --self-check N)";
  }
  if (const int failed = Agree(mpi, code, message, "talus simulate")) return failed;
  const std::string identity = EnsembleIdentity(args, scene);
  if (const std::string root_identity = BroadcastText(mpi, identity); identity != root_identity) {
    code = kExitBadInput;
    message =
        "started with another ensemble than rank 0: " + identity + " instead of " + root_identity;
  }
  if (code == kExitOk && root) {
    message = PrepareOutputDirectory(args.out);
    code = message.empty() ? kExitOk : kExitBadInput;
  }
  if (const int failed = Agree(mpi, code, message, "talus simulate")) return failed;

  const InterruptScope interrupts;
  ProgressBar progress;
  if (root) {
    SetRunLogDirectory(args.out);  // written by main when the run succeeded
    if (const auto stale = RemoveStaleTemporaries(args.out); !stale.empty())
      Say("Removed %zu temporary files of interrupted runs from %s\n", stale.size(),
          args.out.c_str());
    Say("Scene %s: %s; %s; %d ranks\n", args.scene.c_str(), scene.terrain_description.c_str(),
        DescribeRocks(scene).c_str(), mpi.size());
    PrintSceneWarnings(scene);
  }

  // Running: rank r's rocks are [r N / R, (r + 1) N / R), written as a part into a staging
  // directory of its own (rank 0's inside the staging directory of --out).
  const long total = scene.release.total_rocks();
  const long first = total * mpi.rank() / mpi.size();
  const long end = total * (mpi.rank() + 1) / mpi.size();
  std::optional<StagingDirectory> staging, part;
  ensemble::EnsembleReport report;
  VerbHooks hooks;
  // A failed rank removes its temporary files before waiting for the other ranks.
  hooks.on_failure = [&part](bool) { part.reset(); };
  VerbOutcome outcome = RunStaged(
      args.out, staging,
      [&] {
        // Ranks other than 0 stage in $TMPDIR/talus-ranks-<uid>, a directory of this user's alone
        // (never one through a link someone else planted), where they also remove what ranks that
        // died (SIGKILL, a lost node) left there, as rank 0 does in --out.
        const fs::path dir =
            root ? fs::path(args.out)
                 : fs::temp_directory_path() / ("talus-ranks-" + std::to_string(::geteuid()));
        if (!root) {
          MakePrivateDirectory(dir.string());
          RemoveStaleTemporaries(dir.string());
        }
        staging.emplace(dir.string());
        part.emplace(staging->staging_path());
        auto show_progress = [&progress, root](long done, long rocks) {
          ThrowIfInterrupted();
          if (root) progress(done, rocks);
        };
        RunIntoStaging(scene, args.ensemble.threads, first, end, true, *part, show_progress,
                       &report);
      },
      hooks);
  progress.Break();
  if (const int failed = Agree(mpi, outcome.code, outcome.message, "talus simulate")) return failed;

  // Sending the parts to rank 0, rank by rank; then rank 0 merges them into --out.
  std::vector<fs::path> dirs = {part->staging_path()};
  outcome = RunStaged(args.out, staging, [&] {
    for (int r = 1; r < mpi.size(); ++r) {
      if (root) {
        dirs.push_back(fs::path(staging->staging_path()) / ("rank-" + std::to_string(r)));
        ReceivePart(r, dirs.back());
      } else if (mpi.rank() == r) {
        SendPart(part->staging_path());
      }
    }
    if (root) {
      // The parts checked as they were sent, and merged, with talus merge's progress when rank
      // 0's stderr is a terminal (a launcher's pipe is not).
      PhaseProgress merging;
      std::vector<std::string> part_dirs;
      for (const fs::path& dir : dirs) part_dirs.push_back(dir.string());
      const std::vector<io::PartialInfo> parts = ReadParts(part_dirs, std::ref(merging));
      const double wall_time_s =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      ensemble::EnsembleReport merged;
      const std::vector<std::string> files = MergeIntoStaging(
          scene, parts, report.threads, wall_time_s, *staging, &merged, std::ref(merging));
      merging.Break();
      part.reset();
      CommitOutputs(*staging, files, args.out);
      Say("%s on %d ranks\n", merged.BriefReport().c_str(), mpi.size());
      Say("Wrote %zu files to %s\n", files.size(), args.out.c_str());
      PrintRunWarnings(merged, scene);
    }
  });
  part.reset();
  staging.reset();
  return Agree(mpi, outcome.code, outcome.message, "talus simulate");
}

}  // namespace

int RunSimulateOnRanks(const SimulateArgs& args) {
  const MpiSession mpi;
  try {
    return SimulateOnRanks(mpi, args);
  } catch (const Interrupted& e) {
    // A signal while this rank waited for the others (mpirun ends every rank when one dies, and
    // a dead rank never answers): unwinding to here removed this rank's temporary files.
    std::cerr << "talus simulate: rank " << mpi.rank() << ": " << e.what()
              << " while waiting for the other ranks; removed this rank's temporary files\n";
    return ExitCodeForSignal(e.signal());
  }
}

#endif

}  // namespace talus::app
