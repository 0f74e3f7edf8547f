#include "app/mpi_session.hpp"

#if TALUS_HAVE_MPI

#include <chrono>
#include <iostream>
#include <thread>

#include "app/interrupt.hpp"

namespace talus::app {

// Waits for a non-blocking operation without keeping a core busy: a rank that is done waits on a
// node where other ranks (or other jobs) still work, and a blocking MPI call would spin.
// A signal that arrives during the wait ends it (Interrupted): it is how mpirun ends the ranks
// when one has died, and a dead rank never answers. A signal that arrived before the wait was
// seen by the run, which waits here to agree with the others on it.
void Wait(MPI_Request request) {
  const bool signalled_before = PendingSignal() != 0;
  int done = 0;
  MPI_Test(&request, &done, MPI_STATUS_IGNORE);
  while (!done) {
    if (!signalled_before) ThrowIfInterrupted();
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
int Agree(const MpiSession& mpi, int code, const std::string& message, const char* command) {
  std::vector<int> codes(static_cast<std::size_t>(mpi.size()));
  Gather(&code, 1, MPI_INT, codes.data());
  const std::vector<std::string> messages = GatherText(mpi, code != 0 ? message : "");
  int agreed = 0;
  if (mpi.rank() == 0) {
    for (std::size_t r = 0; r < codes.size() && agreed == 0; ++r) {
      if (codes[r] == 0) continue;
      agreed = codes[r];
      std::cerr << command << ": " << (r > 0 ? "rank " + std::to_string(r) + ": " : "")
                << messages[r] << "\n";
    }
  }
  Broadcast(&agreed, 1, MPI_INT);
  return agreed;
}

std::vector<std::string> AllGatherText(const MpiSession& mpi, const std::string& mine) {
  const int length = static_cast<int>(mine.size());
  std::vector<int> lengths(static_cast<std::size_t>(mpi.size())), offsets(lengths.size());
  MPI_Request request;
  MPI_Iallgather(&length, 1, MPI_INT, lengths.data(), 1, MPI_INT, MPI_COMM_WORLD, &request);
  Wait(request);
  int total = 0;
  for (std::size_t r = 0; r < lengths.size(); ++r) {
    offsets[r] = total;
    total += lengths[r];
  }
  std::string all(static_cast<std::size_t>(total), '\0');
  MPI_Iallgatherv(mine.data(), length, MPI_CHAR, all.data(), lengths.data(), offsets.data(),
                  MPI_CHAR, MPI_COMM_WORLD, &request);
  Wait(request);
  std::vector<std::string> texts;
  for (std::size_t r = 0; r < lengths.size(); ++r)
    texts.push_back(
        all.substr(static_cast<std::size_t>(offsets[r]), static_cast<std::size_t>(lengths[r])));
  return texts;
}

}  // namespace talus::app

#endif
