// The main of every benchmark program (bench/CMakeLists.txt): it runs the program's RunBenchmark,
// and what that throws (a bad scene file, a full disk) ends it with one line on stderr.

#include "bench/bench_main.hpp"

#include <sys/resource.h>
#include <sys/utsname.h>

#include <cstdio>
#include <exception>
#include <fstream>
#include <thread>

std::string FirstLine(const std::string& path, const std::string& prefix) {
  std::ifstream in(path);
  for (std::string line; std::getline(in, line);)
    if (line.rfind(prefix, 0) == 0) return line;
  return "unknown";
}

double PeakRssMiB() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_maxrss) / 1024.0;  // kB on Linux
}

void PrintMachine(int argc, char** argv) {
  utsname host{};
  uname(&host);
  std::string model = FirstLine("/proc/cpuinfo", "model name");
  model = model.substr(model.find(':') + 2);
  std::printf("machine: %s, nproc %u, %s %s; load average (1, 5, 15 min) at start: %s\n",
              model.c_str(), std::thread::hardware_concurrency(), host.sysname, host.release,
              FirstLine("/proc/loadavg", "").c_str());
  std::printf("command:");
  for (int k = 0; k < argc; ++k) std::printf(" %s", argv[k]);
  std::printf("\n");
}

int main(int argc, char** argv) {
  try {
    return RunBenchmark(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: %s\n", argv[0], e.what());
    return 1;
  }
}
