#pragma once
// Helpers for the end-to-end tests that run the talus program: a fresh directory, running a
// command with its output and exit status, reading and writing files.

#include <fcntl.h>
#include <signal.h>  // NOLINT(modernize-deprecated-headers): POSIX kill is declared here
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "tests/test_tmp.hpp"

namespace talus::app::testing {

// An empty directory <tmp>/<group>/<name>.
inline std::filesystem::path FreshDir(const std::string& group, const std::string& name) {
  std::filesystem::path dir = talus::testing::TestTmpRoot() / group / name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

// Runs a command; returns its exit status and puts stdout + stderr in *output.
inline int RunCommand(const std::string& command, std::string* output) {
  std::FILE* pipe = ::popen((command + " 2>&1").c_str(), "r");
  std::array<char, 4096> buffer;
  output->clear();
  while (std::size_t n = std::fread(buffer.data(), 1, buffer.size(), pipe))
    output->append(buffer.data(), n);
  const int status = ::pclose(pipe);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// Starts `binary` with `arguments` in the background, its stdout and stderr into `log`; returns
// its process id, or -1 if it could not be started.
inline pid_t StartProgram(const std::string& binary, const std::vector<std::string>& arguments,
                          const std::filesystem::path& log) {
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log.c_str(),
                                   O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  std::vector<std::string> words = {binary};
  words.insert(words.end(), arguments.begin(), arguments.end());
  std::vector<char*> argv;
  for (std::string& word : words) argv.push_back(word.data());
  argv.push_back(nullptr);
  pid_t pid = -1;
  const int error = posix_spawn(&pid, binary.c_str(), &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  return error == 0 ? pid : -1;
}

// How long a test waits for a run it started to reach a point or to end before it calls it hung:
// a bound on a hang, never a timing (the waits end as soon as the run gets there). Generous,
// because the sanitizer build (scripts/sanitize.sh) on a busy machine runs 10-50 x slower than a
// release build.
inline constexpr double kHangSeconds = 900;

// Waits up to `seconds` for `pid` to end; its exit code, 256 + the signal if a signal killed it
// (not an exit code), or -1 if it did not end (it is then killed).
inline int WaitFor(pid_t pid, double seconds) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  int status = 0;
  while (::waitpid(pid, &status, WNOHANG) == 0) {
    if (std::chrono::steady_clock::now() > deadline) {
      ::kill(pid, SIGKILL);
      ::waitpid(pid, &status, 0);
      return -1;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return WIFEXITED(status) ? WEXITSTATUS(status) : 256 + WTERMSIG(status);
}

inline std::string Slurp(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

inline void Write(const std::filesystem::path& path, const std::string& text) {
  std::ofstream(path) << text;
}

// The small slope of the end-to-end tests: a 35 degree plane 20 m long with 10 m of runout, a
// 0.4 x 0.4 x 0.3 m box released at a point and along a line, `rocks` per release, 4 s at most;
// `output` is the [output] section's body, `more` further sections.
inline std::string SmallSlopeScene(int rocks, const std::string& output,
                                   const std::string& more = "") {
  return R"([terrain]
plane = { slope_deg = 35, slope_length_m = 20, runout_m = 10, width_m = 12, cell_m = 1 }
default_ground = "medium_hard"
[rock]
shape = { box = [0.4, 0.4, 0.3] }
[release]
points = [[3, 0]]
lines = [[[4, -2], [4, 2]]]
rocks = )" +
         std::to_string(rocks) + "\n" + more + "[solver]\nmax_time_s = 4\n[output]\n" + output;
}

// The small event of the end-to-end tests, in `dir`: event.toml over scene.toml, three runs of two
// blocks on a short 35 degree slope (each run starts 2 m above the ground, so its first contact
// episode is an impact), observed rest positions and run-outs (observed.csv) and impacts
// (impacts.csv); `event_extra` is appended to event.toml.
inline void WriteSmallEvent(const std::filesystem::path& dir, const std::string& event_extra = "") {
  Write(dir / "scene.toml", R"([terrain]
plane = { slope_deg = 35, slope_length_m = 20, runout_m = 10, width_m = 12, cell_m = 1 }
default_ground = "medium_soft"
[blocks]
file = "blocks.csv"
shape = "box"
[release]
runs = "runs.csv"
rocks = 6
seed = 3
[solver]
max_time_s = 4
)");
  Write(dir / "blocks.csv",
        "block_id,mass_kg,size_x_m,size_y_m,size_z_m\nA,60,0.4,0.4,0.3\n"
        "B,80,0.5,0.4,0.3\n");
  Write(dir / "runs.csv",
        "trajectory_id,x_m,y_m,height_m,vx_mps,block_id\nr1,3,0,2,1,A\n"
        "r2,3,2,2,2,B\nr3,4,-2,2,0,A\n");
  Write(dir / "observed.csv",
        "trajectory_id,x_m,y_m,observed_runout_m\nr1,20,0,17\n"
        "r2,22,2,19\nr3,18,-2,14\n");
  Write(dir / "impacts.csv",
        "trajectory_id,incoming_speed_mps,outgoing_speed_mps\nr1,6,3\n"
        "r2,6.5,3.5\n");
  Write(dir / "event.toml", R"(scene = "scene.toml"
[[observations]]
kind = "runout"
file = "observed.csv"
[[observations]]
kind = "deposits"
file = "observed.csv"
[[observations]]
kind = "impacts"
file = "impacts.csv"
)" + event_extra);
}

// summary.json without what depends on the machine and the split (threads and timings).
inline std::string WithoutTimings(const std::string& summary) {
  nlohmann::ordered_json j = nlohmann::ordered_json::parse(summary);
  for (const char* key : {"threads", "wall_time_s", "trajectories_per_s"}) j.erase(key);
  return j.dump(2);
}

// Every file of `dir` by name, summary.json without timings and without run.log (the command line
// and wall time): what must be byte-identical between runs that differ only in how the rocks were
// split (threads, ranks, parts).
inline std::map<std::string, std::string> OutputsWithoutTimings(const std::filesystem::path& dir) {
  std::map<std::string, std::string> files;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    const std::string name = entry.path().filename().string();
    if (name == "run.log") continue;
    files[name] =
        name == "summary.json" ? WithoutTimings(Slurp(entry.path())) : Slurp(entry.path());
  }
  return files;
}

}  // namespace talus::app::testing
