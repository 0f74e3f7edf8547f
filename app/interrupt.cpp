#include "app/interrupt.hpp"

#include <signal.h>  // NOLINT(modernize-deprecated-headers): POSIX sigaction is declared here

#include <csignal>

namespace talus::app {
namespace {

volatile std::sig_atomic_t g_signal = 0;

extern "C" void RecordSignal(int signal) { g_signal = signal; }

struct sigaction g_previous_int, g_previous_term;

}  // namespace

const char* Interrupted::what() const noexcept {
  return signal_ == SIGTERM ? "interrupted by SIGTERM" : "interrupted by SIGINT";
}

std::string InterruptedMessage(const Interrupted& e, const std::string& out) {
  return std::string(e.what()) + "; removed this run's temporary files, " + out +
         " is as it was before the run";
}

InterruptScope::InterruptScope() {
  g_signal = 0;
  struct sigaction action = {};
  action.sa_handler = RecordSignal;
  sigemptyset(&action.sa_mask);
  // SA_RESETHAND: a second signal has its default effect. SA_RESTART: no EINTR in the writers.
  action.sa_flags = SA_RESETHAND | SA_RESTART;
  sigaction(SIGINT, &action, &g_previous_int);
  sigaction(SIGTERM, &action, &g_previous_term);
}

InterruptScope::~InterruptScope() {
  sigaction(SIGINT, &g_previous_int, nullptr);
  sigaction(SIGTERM, &g_previous_term, nullptr);
}

int PendingSignal() { return g_signal; }

void ThrowIfInterrupted() {
  if (const int signal = g_signal; signal != 0) throw Interrupted(signal);
}

}  // namespace talus::app
