#include "app/console.hpp"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <mutex>
#include <vector>

#include "common/atomic_file.hpp"
#include "talus/version.hpp"

namespace talus::app {
namespace {

struct ConsoleState {
  std::mutex mutex;
  bool quiet = false;
  bool status_shown = false;
  std::string command_line = "talus";
  std::string started;  // UTC, ISO 8601
  std::chrono::steady_clock::time_point t0 = std::chrono::steady_clock::now();
  std::string kept;
  std::string log_directory;
};

ConsoleState& State() {
  static ConsoleState state;
  return state;
}

// Ends the status line; the caller holds the mutex.
void EndStatusLocked(ConsoleState& s) {
  if (!s.status_shown) return;
  std::fputs("\n", stderr);
  std::fflush(stderr);
  s.status_shown = false;
}

void ToStderr(const std::string& line) {
  ConsoleState& s = State();
  const std::lock_guard lock(s.mutex);
  EndStatusLocked(s);
  std::fflush(stdout);  // what was said before comes before
  std::fputs(line.c_str(), stderr);
  std::fflush(stderr);
  s.kept += line;
}

// A command-line word as a shell reads it back: quoted when it holds anything but safe characters.
std::string ShellWord(const std::string& word) {
  const bool safe = !word.empty() && word.find_first_not_of(
                                         "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ"
                                         "0123456789_-+=./:,@%") == std::string::npos;
  if (safe) return word;
  std::string out = "'";
  for (char c : word) {
    if (c == '\'')
      out += "'\\''";
    else
      out += c;
  }
  out += '\'';
  return out;
}

}  // namespace

void SetQuiet(bool quiet) { State().quiet = quiet; }
bool Quiet() { return State().quiet; }

void SetCommandLine(int argc, const char* const* argv) {
  ConsoleState& s = State();
  s.command_line.clear();
  for (int k = 0; k < argc; ++k) {
    if (k > 0) s.command_line += ' ';
    s.command_line += ShellWord(argv[k]);
  }
  const std::time_t now = std::time(nullptr);
  char stamp[32];
  std::strftime(stamp, sizeof stamp, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&now));
  s.started = stamp;
  s.t0 = std::chrono::steady_clock::now();
}

void Say(const char* format, ...) {
  std::va_list args;
  va_start(args, format);
  std::va_list copy;
  va_copy(copy, args);
  const int n = std::vsnprintf(nullptr, 0, format, copy);
  va_end(copy);
  std::string text(n > 0 ? static_cast<std::size_t>(n) : 0, '\0');
  if (n > 0) std::vsnprintf(text.data(), text.size() + 1, format, args);
  va_end(args);
  ConsoleState& s = State();
  const std::lock_guard lock(s.mutex);
  s.kept += text;
  if (s.quiet) return;
  EndStatusLocked(s);
  std::fputs(text.c_str(), stdout);
  std::fflush(stdout);
}

void Warn(const std::string& verb, const std::string& text) {
  ToStderr("talus " + verb + ": WARNING: " + text + "\n");
}

void Fail(const std::string& verb, const std::string& message) {
  ToStderr("talus " + verb + ": " + message + "\n");
}

bool ShowsProgress() { return !State().quiet && ::isatty(STDERR_FILENO) != 0; }

void Status(const std::string& text) {
  if (!ShowsProgress()) return;
  ConsoleState& s = State();
  const std::lock_guard lock(s.mutex);
  std::fflush(stdout);
  std::fprintf(stderr, "\r%s\033[K", text.c_str());  // the rest of the old line cleared
  std::fflush(stderr);
  s.status_shown = true;
}

void EndStatus() {
  ConsoleState& s = State();
  const std::lock_guard lock(s.mutex);
  EndStatusLocked(s);
}

std::string ProgressLine(const std::string& label, double done, double total,
                         const std::string& unit, int decimals, double elapsed_s) {
  constexpr int kWidth = 30;
  const double fraction = total > 0 ? std::clamp(done / total, 0.0, 1.0) : 0.0;
  const int filled = static_cast<int>(kWidth * fraction);
  const double rate = elapsed_s > 0 ? done / elapsed_s : 0.0;
  const std::string left =
      done > 0 && rate > 0 ? std::to_string(std::lround((total - done) / rate)) + " s" : "?";
  char line[160];
  std::snprintf(line, sizeof line, "[%-*.*s] %.*f/%.*f %s  %.1f/s  %s left", kWidth, filled,
                "##############################", decimals, done, decimals, total, unit.c_str(),
                rate, left.c_str());
  return label.empty() ? std::string(line) : label + " " + line;
}

void SetRunLogDirectory(const std::string& dir) { State().log_directory = dir; }

std::string RunLogText(int exit_code) {
  ConsoleState& s = State();
  const std::lock_guard lock(s.mutex);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - s.t0).count();
  char finished[96];
  std::snprintf(finished, sizeof finished, "finished: exit %d after %.2f s\n", exit_code, seconds);
  std::string text = std::string("talus ") + kVersion + "\ncommand: " + s.command_line +
                     "\nstarted: " + s.started + "\n\n" + s.kept;
  if (!s.kept.empty() && s.kept.back() != '\n') text += "\n";
  return text + "\n" + finished;
}

void WriteRunLog(int exit_code) {
  const std::string dir = State().log_directory;
  if (exit_code != 0 || dir.empty()) return;
  try {
    WriteFileAtomically((std::filesystem::path(dir) / kRunLog).string(), RunLogText(exit_code));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "talus: WARNING: run.log not written: %s\n", e.what());
  }
}

}  // namespace talus::app
