// SIGINT and SIGTERM inside an InterruptScope are recorded, not fatal; the run asks for them at
// its safe points; the previous handlers come back when the scope ends.

#include "app/interrupt.hpp"

#include <gtest/gtest.h>
#include <signal.h>  // NOLINT(modernize-deprecated-headers): POSIX sigaction is declared here

#include <csignal>
#include <string>

#include "app/commands.hpp"

namespace talus::app {
namespace {

volatile std::sig_atomic_t g_outer = 0;
extern "C" void OuterHandler(int signal) { g_outer = signal; }

TEST(InterruptScope, RecordsSigintAndThrowsItAtTheNextSafePoint) {
  InterruptScope scope;
  EXPECT_EQ(PendingSignal(), 0);
  EXPECT_NO_THROW(ThrowIfInterrupted());
  std::raise(SIGINT);  // the process goes on
  EXPECT_EQ(PendingSignal(), SIGINT);
  try {
    ThrowIfInterrupted();
    ADD_FAILURE() << "no Interrupted";
  } catch (const Interrupted& e) {
    EXPECT_EQ(e.signal(), SIGINT);
    EXPECT_STREQ(e.what(), "interrupted by SIGINT");
    EXPECT_EQ(ExitCodeForSignal(e.signal()), 130);
    EXPECT_EQ(InterruptedMessage(e, "out/tirol"),
              "interrupted by SIGINT; removed this run's temporary files, out/tirol is as it was "
              "before the run");
  }
}

TEST(InterruptScope, RecordsSigtermAndANewScopeStartsClean) {
  {
    InterruptScope scope;
    std::raise(SIGTERM);
    EXPECT_EQ(PendingSignal(), SIGTERM);
    try {
      ThrowIfInterrupted();
      ADD_FAILURE() << "no Interrupted";
    } catch (const Interrupted& e) {
      EXPECT_STREQ(e.what(), "interrupted by SIGTERM");
      EXPECT_EQ(ExitCodeForSignal(e.signal()), 143);
    }
  }
  InterruptScope next;
  EXPECT_EQ(PendingSignal(), 0);
  EXPECT_NO_THROW(ThrowIfInterrupted());
}

TEST(InterruptScope, RestoresThePreviousHandlersWhenItEnds) {
  struct sigaction outer = {};
  outer.sa_handler = OuterHandler;
  sigemptyset(&outer.sa_mask);
  struct sigaction saved_int, saved_term;
  ASSERT_EQ(sigaction(SIGINT, &outer, &saved_int), 0);
  ASSERT_EQ(sigaction(SIGTERM, &outer, &saved_term), 0);
  {
    InterruptScope scope;
    std::raise(SIGINT);
    EXPECT_EQ(g_outer, 0);  // the scope's handler took it
  }
  std::raise(SIGINT);
  EXPECT_EQ(g_outer, SIGINT);  // the outer handler is back
  std::raise(SIGTERM);
  EXPECT_EQ(g_outer, SIGTERM);
  sigaction(SIGINT, &saved_int, nullptr);
  sigaction(SIGTERM, &saved_term, nullptr);
}

}  // namespace
}  // namespace talus::app
