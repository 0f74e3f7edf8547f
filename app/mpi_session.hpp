#pragma once
// MPI for talus's commands under mpirun / srun (simulate_mpi.cpp, calibrate_command.cpp): a session
// for the length of a command, and the few collective operations they use. Every wait polls
// (MPI_Test and a short sleep) so that a rank that is done does not keep a core busy. Only with
// TALUS_HAVE_MPI.

#if TALUS_HAVE_MPI

#include <mpi.h>

#include <string>
#include <vector>

namespace talus::app {

// MPI for the length of a command: initialised, and finalised on every way out.
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
void Wait(MPI_Request request);

// Gather to rank 0, broadcast from rank 0, send to rank 0, receive from `from` (tag 0).
void Gather(const void* mine, int count, MPI_Datatype type, void* all);
void Broadcast(void* data, int count, MPI_Datatype type);
void Send(const void* data, int count, MPI_Datatype type);
void Receive(void* data, int count, MPI_Datatype type, int from);

// Every rank's text, on rank 0 (empty elsewhere).
std::vector<std::string> GatherText(const MpiSession& mpi, const std::string& mine);

// Rank 0's text on every rank.
std::string BroadcastText(const MpiSession& mpi, std::string text);

// The ranks agree on how a step went: the exit code of the first rank that failed (0 when none
// did), the same on every rank; rank 0 prints that rank's message.
int Agree(const MpiSession& mpi, int code, const std::string& message, const char* command);

// Every rank's text, in rank order, on every rank.
std::vector<std::string> AllGatherText(const MpiSession& mpi, const std::string& mine);

}  // namespace talus::app

#endif
