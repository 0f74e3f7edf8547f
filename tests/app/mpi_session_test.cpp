// The MPI collectives of talus's commands (app/mpi_session.hpp) for any number of ranks: run as
// one process (MPI's singleton: each rank's result is its own) by gtest_discover_tests, and under
// mpiexec with 2 and 3 ranks (tests/app/CMakeLists.txt), where every rank checks its part.

#include "app/mpi_session.hpp"

#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

namespace talus::app {
namespace {

// One session for the process (MPI may be initialised once), finalised after the tests.
MpiSession* session = nullptr;

class MpiEnvironment : public ::testing::Environment {
 public:
  void SetUp() override { session = new MpiSession(); }
  void TearDown() override {
    delete session;
    session = nullptr;
  }
};
const auto* const kEnvironment = ::testing::AddGlobalTestEnvironment(new MpiEnvironment);

// Texts of different lengths per rank (rank r: r + 1 letters, the empty text on rank 1): the
// offsets must come out right.
std::string TextOf(int rank) { return rank == 1 ? "" : std::string(rank + 1, 'a' + rank % 26); }

TEST(MpiSession, RankIsWithinSize) {
  ASSERT_NE(session, nullptr);
  EXPECT_GE(session->size(), 1);
  EXPECT_GE(session->rank(), 0);
  EXPECT_LT(session->rank(), session->size());
}

TEST(MpiSession, GatherTextGivesEveryRanksTextOnRankZeroInRankOrder) {
  const std::vector<std::string> all = GatherText(*session, TextOf(session->rank()));
  if (session->rank() != 0) {
    EXPECT_TRUE(all.empty());
    return;
  }
  ASSERT_EQ(static_cast<int>(all.size()), session->size());
  for (int r = 0; r < session->size(); ++r) EXPECT_EQ(all[static_cast<std::size_t>(r)], TextOf(r));
}

TEST(MpiSession, AllGatherTextGivesEveryRanksTextEverywhere) {
  const std::vector<std::string> all = AllGatherText(*session, TextOf(session->rank()));
  ASSERT_EQ(static_cast<int>(all.size()), session->size());
  for (int r = 0; r < session->size(); ++r) EXPECT_EQ(all[static_cast<std::size_t>(r)], TextOf(r));
}

TEST(MpiSession, BroadcastTextGivesRankZerosTextEverywhere) {
  const std::string mine = session->rank() == 0 ? std::string("scene of rank 0\n\0x", 18)
                                                : "something else, longer than rank 0's text";
  EXPECT_EQ(BroadcastText(*session, mine), std::string("scene of rank 0\n\0x", 18));
  EXPECT_EQ(BroadcastText(*session, session->rank() == 0 ? "" : "not empty"), "");
}

// The first failing rank's code on every rank; 0 when none failed. Rank r fails with 10 + r when
// r is the last rank (one rank alone: it fails); then every rank fails and rank 0's code wins.
TEST(MpiSession, AgreeGivesTheFirstFailingRanksCodeEverywhere) {
  const int rank = session->rank(), last = session->size() - 1;
  EXPECT_EQ(Agree(*session, 0, "", "test"), 0);
  EXPECT_EQ(Agree(*session, rank == last ? 10 + rank : 0, "failed", "test"), 10 + last);
  EXPECT_EQ(Agree(*session, 20 + rank, "all failed", "test"), 20);
}

// Raw collectives: Gather of ints, Broadcast, and Send / Receive from every rank to rank 0.
TEST(MpiSession, GatherBroadcastSendAndReceive) {
  const int rank = session->rank(), size = session->size();
  const int mine = 100 + rank;
  std::vector<int> all(static_cast<std::size_t>(size), -1);
  Gather(&mine, 1, MPI_INT, all.data());
  if (rank == 0) {
    for (int r = 0; r < size; ++r) EXPECT_EQ(all[static_cast<std::size_t>(r)], 100 + r);
  }
  double value = rank == 0 ? 2.5 : -1;
  Broadcast(&value, 1, MPI_DOUBLE);
  EXPECT_EQ(value, 2.5);
  if (rank == 0) {
    for (int from = 1; from < size; ++from) {
      long got = 0;
      Receive(&got, 1, MPI_LONG, from);
      EXPECT_EQ(got, 1000L * from);
    }
  } else {
    const long sent = 1000L * rank;
    Send(&sent, 1, MPI_LONG);
  }
}

}  // namespace
}  // namespace talus::app
