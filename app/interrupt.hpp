#pragma once
// SIGINT and SIGTERM during a run. The handler only records the signal (async-signal-safe); the
// run checks it at safe points (ThrowIfInterrupted: the ensemble's progress callback, each
// finished rock, between outputs), unwinds so that its temporary files are removed, and the verb
// exits with ExitCodeForSignal (130, 143). A second signal is not caught: it ends the process at
// once (a later run removes what it left, RemoveStaleTemporaries).

#include <exception>
#include <string>

namespace talus::app {

// Thrown by ThrowIfInterrupted.
class Interrupted : public std::exception {
 public:
  explicit Interrupted(int signal) : signal_(signal) {}
  int signal() const { return signal_; }
  const char* what() const noexcept override;  // "interrupted by SIGINT" (or SIGTERM)

 private:
  int signal_;
};

// What a verb says when a signal ended it after it removed its temporary files: "interrupted by
// SIGINT; removed this run's temporary files, <out> is as it was before the run".
std::string InterruptedMessage(const Interrupted& e, const std::string& out);

// Catches SIGINT and SIGTERM while alive; restores the previous handlers when destroyed.
class InterruptScope {
 public:
  InterruptScope();
  ~InterruptScope();
  InterruptScope(const InterruptScope&) = delete;
  InterruptScope& operator=(const InterruptScope&) = delete;
};

// Throws Interrupted when SIGINT or SIGTERM arrived inside an InterruptScope.
void ThrowIfInterrupted();
// The signal that arrived inside the current InterruptScope, or 0.
int PendingSignal();

}  // namespace talus::app
