#include "app/run_verb.hpp"

#include <csignal>
#include <cstdio>
#include <exception>
#include <iostream>

#include "app/commands.hpp"
#include "app/console.hpp"
#include "common/error.hpp"

namespace talus::app {

VerbOutcome RunStaged(const std::string& out, std::optional<StagingDirectory>& staging,
                      const std::function<void()>& work, const VerbHooks& hooks) {
  VerbOutcome outcome;
  bool interrupted = false;
  try {
    work();
    return outcome;
  } catch (const Interrupted& e) {
    interrupted = true;
    outcome.code = ExitCodeForSignal(e.signal());
    outcome.message =
        hooks.interrupted_message ? hooks.interrupted_message(e) : InterruptedMessage(e, out);
  } catch (const InputError& e) {
    outcome.code = hooks.late_input_errors ? kExitBadInput : kExitRunFailed;
    outcome.message = (hooks.late_input_errors || !staging ? std::string(e.what())
                                                           : staging->Describe(e.what())) +
                      " (no output written)";
  } catch (const std::exception& e) {
    outcome.code = kExitRunFailed;
    outcome.message =
        (staging ? staging->Describe(e.what()) : std::string(e.what())) + " (no output written)";
  }
  staging.reset();
  if (hooks.on_failure) hooks.on_failure(interrupted);
  return outcome;
}

int RunVerb(const Verb& verb, const std::function<void(std::optional<StagingDirectory>&)>& work) {
  const auto fail = [&verb](const std::string& message) { Fail(verb.name, message); };
  std::string why = PrepareOutputDirectory(verb.out);
  if (why.empty() && verb.checks) why = verb.checks();
  if (!why.empty()) {
    fail(why);
    return kExitBadInput;
  }
  SetRunLogDirectory(verb.out);  // written by main when the verb succeeded
  // From here on SIGINT / SIGTERM unwind the run: no temporary file is left behind.
  const InterruptScope interrupts;
  std::signal(SIGXFSZ, SIG_IGN);  // a file-size limit is a write error ("File too large")
  const auto stale = RemoveStaleTemporaries(verb.out);
  if (verb.say_removed_temporaries && !stale.empty())
    Say("Removed %zu temporary files of interrupted runs from %s\n", stale.size(),
        verb.out.c_str());
  std::optional<StagingDirectory> staging;
  const VerbOutcome outcome = RunStaged(
      verb.out, staging, [&] { work(staging); }, verb.hooks);
  if (outcome.code != kExitOk) fail(outcome.message);
  return outcome.code;
}

}  // namespace talus::app
