// The main of every benchmark program (bench/CMakeLists.txt): it runs the program's RunBenchmark,
// and what that throws (a bad scene file, a full disk) ends it with one line on stderr.

#include <cstdio>
#include <exception>

#include "bench/bench_main.hpp"

int main(int argc, char** argv) {
  try {
    return RunBenchmark(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: %s\n", argv[0], e.what());
    return 1;
  }
}
