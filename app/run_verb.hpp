#pragma once
// The ladder every verb that writes into --out climbs (simulate, validate, merge, calibrate):
// prepare --out, catch SIGINT / SIGTERM, stage every output and commit them together, and turn an
// interruption or a failure into an exit code and one message, leaving --out as it was.

#include <functional>
#include <optional>
#include <string>

#include "app/interrupt.hpp"
#include "common/atomic_file.hpp"

namespace talus::app {

// How a verb's run ended: its exit code (commands.hpp) and, unless kExitOk, what to say.
struct VerbOutcome {
  int code = 0;
  std::string message;
};

// What a verb adds to the ladder.
struct VerbHooks {
  // Called when the run failed (interrupted: by a signal), after the staging directory was
  // removed and before the message is said: e.g. end a progress line, keep a checkpoint.
  std::function<void(bool interrupted)> on_failure = {};
  // The message of an interruption; default InterruptedMessage(e, out).
  std::function<std::string(const Interrupted&)> interrupted_message = {};
  // Bad input found only while running (a rock shape per rock that cannot be built) is
  // kExitBadInput, "<what> (no output written)"; otherwise it fails the run as any error does.
  bool late_input_errors = false;
};

// Runs `work`, which emplaces `staging` (a staging directory in `out`) when it starts writing,
// writes its outputs there and commits them, and turns what it throws into the outcome. Before it
// returns a failure, the staging directory and every temporary file in it are removed:
// - Interrupted: 128 + the signal, "interrupted by SIGINT; removed this run's temporary files,
//   <out> is as it was before the run";
// - any other exception: kExitRunFailed, "<what> (no output written)", where a path inside the
//   staging directory is named as the file in `out` it would have become.
VerbOutcome RunStaged(const std::string& out, std::optional<StagingDirectory>& staging,
                      const std::function<void()>& work, const VerbHooks& hooks = {});

// A verb on one process that writes into `out`: `checks` (bad input found once --out exists,
// e.g. a run too large for the disk: "" when none) and then `work` as RunStaged runs it, with
// SIGINT / SIGTERM caught (interrupt.hpp), a file-size limit reported as a write error and the
// temporary files of killed runs removed from `out` first. Returns the exit code; a failure is
// said on stderr as "talus <verb>: <message>".
struct Verb {
  std::string name;  // "simulate"
  std::string out;   // --out
  std::function<std::string()> checks = {};
  // Say "Removed N temporary files of interrupted runs from <out>" when there were some.
  bool say_removed_temporaries = false;
  VerbHooks hooks = {};
};
int RunVerb(const Verb& verb, const std::function<void(std::optional<StagingDirectory>&)>& work);

}  // namespace talus::app
