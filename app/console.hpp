#pragma once
// What the talus program tells its user, in one place: information on stdout, progress as a status
// line on stderr (only on a terminal), warnings and errors on stderr. --quiet silences the
// information and the progress, never a warning or an error. Everything but the progress is also
// kept, and a verb that writes into --out leaves it there as run.log when it succeeded: the
// version, the command line, what was printed and the wall time.

#include <string>

namespace talus::app {

// --quiet: no information and no progress.
void SetQuiet(bool quiet);
bool Quiet();
// The command line and the start time, for run.log (main calls it once).
void SetCommandLine(int argc, const char* const* argv);

// Information for people, printf-style: on stdout unless --quiet; kept for run.log.
void Say(const char* format, ...) __attribute__((format(printf, 1, 2)));
// "talus <verb>: WARNING: <text>" on stderr; kept.
void Warn(const std::string& verb, const std::string& text);
// "talus <verb>: <message>" on stderr; kept.
void Fail(const std::string& verb, const std::string& message);

// Whether progress is shown: stderr is a terminal and not --quiet.
bool ShowsProgress();
// Replaces the status line with `text` (ShowsProgress() only; never kept).
void Status(const std::string& text);
// Ends a shown status line, so that what follows starts on a line of its own.
void EndStatus();
// A progress status line: "<label> [##########          ] <done>/<total> <unit>  <rate>/s  <n> s
// left" (without a label it starts at the bar): done and total with `decimals` digits, the rate
// per second so far with one, the time left at that rate ("?" before anything is done).
std::string ProgressLine(const std::string& label, double done, double total,
                         const std::string& unit, int decimals, double elapsed_s);

// The directory run.log goes into when the verb succeeds (its --out); unset: no run.log (a verb
// without --out, a rank other than 0).
// The log a verb that succeeded leaves in its --out (WriteRunLog).
inline constexpr const char* kRunLog = "run.log";
void SetRunLogDirectory(const std::string& dir);
// run.log's text: version, command line, start time, every kept line, then "finished: exit
// <code> after <s> s".
std::string RunLogText(int exit_code);
// Writes run.log into the directory set above when `exit_code` is 0 (a failed run leaves --out as
// it was), completely or not at all; a failure to write it is a warning, not a failed run.
void WriteRunLog(int exit_code);

}  // namespace talus::app
