// talus simulate under mpirun / srun: the rocks are divided among the ranks in contiguous ranges,
// each rank runs its range with its threads into a part (io/partial.hpp) in a private staging
// directory, sends the part's files to rank 0, and rank 0 merges the parts into --out with the
// code of `talus merge`. The ranks agree on success at every step (loading, running, sending), so
// that a failure on any rank ends every rank with one message from rank 0 and no output.

#include <chrono>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "app/commands.hpp"
#include "app/interrupt.hpp"
#include "app/run_outputs.hpp"
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

#if !TALUS_HAVE_MPI

int RunSimulateOnRanks(const SimulateArgs&) {
  const char* rank = std::getenv("OMPI_COMM_WORLD_RANK");
  if (!rank || std::atoi(rank) == 0)
    std::cerr << "talus simulate: started as " << LaunchedRanks()
              << " MPI processes, but this talus was built without MPI (configure with "
                 "-DTALUS_WITH_MPI=ON, or run one process)\n";
  return kExitBadInput;
}

#else

namespace {

namespace fs = std::filesystem;

// MPI for the length of a run: initialised, and finalised on every way out.
class MpiSession {
 public:
  MpiSession() {
    MPI_Init(nullptr, nullptr);
    MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
    MPI_Comm_size(MPI_COMM_WORLD, &size_);
  }
  ~MpiSession() { MPI_Finalize(); }
  MpiSession(const MpiSession&) = delete;
  MpiSession& operator=(const MpiSession&) = delete;
  int rank() const { return rank_; }
  int size() const { return size_; }

 private:
  int rank_ = 0, size_ = 1;
};

// Waits for a non-blocking operation without keeping a core busy: a rank that is done waits on a
// node where other ranks (or other jobs) still work, and a blocking MPI call would spin.
void Wait(MPI_Request request) {
  int done = 0;
  MPI_Test(&request, &done, MPI_STATUS_IGNORE);
  while (!done) {
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
    MPI_Test(&request, &done, MPI_STATUS_IGNORE);
  }
}

void Gather(const void* mine, int count, MPI_Datatype type, void* all) {
  MPI_Request request;
  MPI_Igather(mine, count, type, all, count, type, 0, MPI_COMM_WORLD, &request);
  Wait(request);
}

void Broadcast(void* data, int count, MPI_Datatype type) {
  MPI_Request request;
  MPI_Ibcast(data, count, type, 0, MPI_COMM_WORLD, &request);
  Wait(request);
}

void Send(const void* data, int count, MPI_Datatype type) {
  MPI_Request request;
  MPI_Isend(data, count, type, 0, 0, MPI_COMM_WORLD, &request);
  Wait(request);
}

void Receive(void* data, int count, MPI_Datatype type, int from) {
  MPI_Request request;
  MPI_Irecv(data, count, type, from, 0, MPI_COMM_WORLD, &request);
  Wait(request);
}

// Every rank's text, on rank 0 (empty elsewhere).
std::vector<std::string> GatherText(const MpiSession& mpi, const std::string& mine) {
  const int length = static_cast<int>(mine.size());
  std::vector<int> lengths(static_cast<std::size_t>(mpi.size())), offsets(lengths.size());
  Gather(&length, 1, MPI_INT, lengths.data());
  int total = 0;
  for (std::size_t r = 0; r < lengths.size(); ++r) {
    offsets[r] = total;
    total += lengths[r];
  }
  std::string all(mpi.rank() == 0 ? static_cast<std::size_t>(total) : 0, '\0');
  MPI_Request request;
  MPI_Igatherv(mine.data(), length, MPI_CHAR, all.data(), lengths.data(), offsets.data(), MPI_CHAR,
               0, MPI_COMM_WORLD, &request);
  Wait(request);
  std::vector<std::string> texts;
  if (mpi.rank() == 0)
    for (std::size_t r = 0; r < lengths.size(); ++r)
      texts.push_back(
          all.substr(static_cast<std::size_t>(offsets[r]), static_cast<std::size_t>(lengths[r])));
  return texts;
}

// Rank 0's text on every rank.
std::string BroadcastText(const MpiSession& mpi, std::string text) {
  int length = static_cast<int>(text.size());
  Broadcast(&length, 1, MPI_INT);
  if (mpi.rank() != 0) text.assign(static_cast<std::size_t>(length), '\0');
  Broadcast(text.data(), length, MPI_CHAR);
  return text;
}

// The ranks agree on how a step went: the exit code of the first rank that failed (0 when none
// did), the same on every rank; rank 0 prints that rank's message.
int Agree(const MpiSession& mpi, int code, const std::string& message) {
  std::vector<int> codes(static_cast<std::size_t>(mpi.size()));
  Gather(&code, 1, MPI_INT, codes.data());
  const std::vector<std::string> messages = GatherText(mpi, code != 0 ? message : "");
  int agreed = 0;
  if (mpi.rank() == 0) {
    for (std::size_t r = 0; r < codes.size() && agreed == 0; ++r) {
      if (codes[r] == 0) continue;
      agreed = codes[r];
      std::cerr << "talus simulate: " << (r > 0 ? "rank " + std::to_string(r) + ": " : "")
                << messages[r] << "\n";
    }
  }
  Broadcast(&agreed, 1, MPI_INT);
  return agreed;
}

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
         std::to_string(scene.release.total_rocks()) + " rocks, --out " +
         fs::absolute(args.out).lexically_normal().string();
}

}  // namespace

int RunSimulateOnRanks(const SimulateArgs& args) {
  const auto t0 = std::chrono::steady_clock::now();
  const MpiSession mpi;
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
  if (const int failed = Agree(mpi, code, message)) return failed;
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
  if (const int failed = Agree(mpi, code, message)) return failed;

  const InterruptScope interrupts;
  std::signal(SIGXFSZ, SIG_IGN);  // a file-size limit is a write error ("File too large")
  ProgressBar progress;
  if (root) {
    if (const auto stale = RemoveStaleTemporaries(args.out); !stale.empty())
      std::printf("Removed %zu temporary files of interrupted runs from %s\n", stale.size(),
                  args.out.c_str());
    std::printf("Scene %s: %s; %s; %d ranks\n", args.scene.c_str(),
                scene.terrain_description.c_str(), DescribeRocks(scene).c_str(), mpi.size());
    std::fflush(stdout);
  }

  // Running: rank r's rocks are [r N / R, (r + 1) N / R), written as a part into a staging
  // directory of its own (rank 0's inside the staging directory of --out).
  const long total = scene.release.total_rocks();
  const long first = total * mpi.rank() / mpi.size();
  const long end = total * (mpi.rank() + 1) / mpi.size();
  std::optional<StagingDirectory> staging, part;
  ensemble::EnsembleReport report;
  try {
    // Ranks other than 0 stage in $TMPDIR/talus-ranks, where they also remove what ranks that
    // died (SIGKILL, a lost node) left there, as rank 0 does in --out.
    const fs::path dir = root ? fs::path(args.out) : fs::temp_directory_path() / "talus-ranks";
    if (!root) {
      fs::create_directories(dir);
      RemoveStaleTemporaries(dir.string());
    }
    staging.emplace(dir.string());
    part.emplace(staging->staging_path());
    auto show_progress = [&progress, root](long done, long rocks) {
      ThrowIfInterrupted();
      if (root) progress(done, rocks);
    };
    RunIntoStaging(scene, args.threads, first, end, true, *part, show_progress, &report);
  } catch (const Interrupted& e) {
    code = ExitCodeForSignal(e.signal());
    message = std::string(e.what()) + "; removed this run's temporary files, " + args.out +
              " is as it was before the run";
  } catch (const std::exception& e) {
    code = kExitRunFailed;
    message =
        (staging ? staging->Describe(e.what()) : std::string(e.what())) + " (no output written)";
  }
  progress.Break();
  if (code != kExitOk) {  // remove the temporary files before waiting for the other ranks
    part.reset();
    staging.reset();
  }
  if (const int failed = Agree(mpi, code, message)) return failed;

  // Sending the parts to rank 0, rank by rank; then rank 0 merges them into --out.
  std::vector<fs::path> dirs = {part->staging_path()};
  try {
    for (int r = 1; r < mpi.size(); ++r) {
      if (root) {
        dirs.push_back(fs::path(staging->staging_path()) / ("rank-" + std::to_string(r)));
        ReceivePart(r, dirs.back());
      } else if (mpi.rank() == r) {
        SendPart(part->staging_path());
      }
    }
    if (root) {
      std::vector<io::PartialInfo> parts;
      for (const fs::path& dir : dirs) parts.push_back(io::ReadPartialInfo(dir.string()));
      parts = io::CheckPartials(std::move(parts));
      const double wall_time_s =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      ensemble::EnsembleReport merged;
      const std::vector<std::string> files =
          MergeIntoStaging(scene, parts, report.threads, wall_time_s, *staging, &merged);
      part.reset();
      CommitOutputs(*staging, files, args.out);
      std::printf("%s on %d ranks\n", merged.BriefReport().c_str(), mpi.size());
      std::printf("Wrote %zu files to %s\n", files.size(), args.out.c_str());
      if (merged.count(EndReason::kFailed) > 0)
        std::fprintf(stderr,
                     "talus simulate: %ld rocks failed numerically (end = failed in rocks.csv)\n",
                     merged.count(EndReason::kFailed));
    }
    code = kExitOk;
  } catch (const Interrupted& e) {
    code = ExitCodeForSignal(e.signal());
    message = std::string(e.what()) + "; removed this run's temporary files, " + args.out +
              " is as it was before the run";
  } catch (const std::exception& e) {
    code = kExitRunFailed;
    message = staging->Describe(e.what()) + " (no output written)";
  }
  part.reset();
  staging.reset();
  return Agree(mpi, code, message);
}

#endif

}  // namespace talus::app
