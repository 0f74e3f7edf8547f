// Checks of command-line values shared by the verbs, with messages that name the bound.

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cstring>
#include <filesystem>
#include <string>
#include <thread>

#include "app/commands.hpp"

namespace talus::app {

CLI::Validator IntegerRange(long long min, long long max) {
  const std::string description =
      "INT in [" + std::to_string(min) + " .. " + std::to_string(max) + "]";
  return CLI::Validator(
      [min, max](std::string& text) -> std::string {
        long long value = 0;
        const char* last = text.data() + text.size();
        const auto [end, error] = std::from_chars(text.data(), last, value);
        if (error == std::errc::result_out_of_range)
          return (text[0] == '-' ? "must be >= " + std::to_string(min)
                                 : "must be <= " + std::to_string(max)) +
                 ", got " + text;
        if (error != std::errc() || end != last || text.empty())
          return "must be an integer, got '" + text + "'";
        if (value < min) return "must be >= " + std::to_string(min) + ", got " + text;
        if (value > max) return "must be <= " + std::to_string(max) + ", got " + text;
        return {};
      },
      description);
}

int MaxThreads() {
  const int cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  return std::max(kMinMaxThreads, kThreadsPerCore * cores);
}

CLI::Validator ThreadCount() {
  const int max = MaxThreads();
  const int cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  const CLI::Validator range = IntegerRange(0, max);
  return CLI::Validator(
      [range, cores](std::string& text) -> std::string {
        std::string why = range(text);
        if (why.rfind("must be <=", 0) == 0)
          why += " (this machine has " + std::to_string(cores) + " cores; at most " +
                 std::to_string(kThreadsPerCore) + " threads per core, or " +
                 std::to_string(kMinMaxThreads) + ", are allowed: more threads only cost memory)";
        return why;
      },
      "INT in [0 .. " + std::to_string(max) + "], 0: one per core");
}

std::string PrepareOutputDirectory(const std::string& dir) {
  namespace fs = std::filesystem;
  std::error_code error;
  if (fs::exists(dir, error) && !fs::is_directory(dir, error))
    return "--out " + dir + " exists and is not a directory";
  fs::create_directories(dir, error);
  if (error) return "cannot create the output directory " + dir + ": " + error.message();
  if (::access(dir.c_str(), W_OK | X_OK) != 0)
    return "cannot write to the output directory " + dir + ": " + std::strerror(errno);
  return "";
}

}  // namespace talus::app
