#pragma once
// Each benchmark program defines RunBenchmark; bench_main.cpp's main runs it.

#include <string>

// Parses the command line, runs the benchmark and prints its figures; the exit code.
int RunBenchmark(int argc, char** argv);

// The first line of the file at `path` that starts with `prefix` ("unknown" when none does).
std::string FirstLine(const std::string& path, const std::string& prefix);

// Prints the machine (CPU model, hardware threads, kernel, load average) and the command line.
void PrintMachine(int argc, char** argv);

// The process's peak resident memory so far (getrusage ru_maxrss), MiB.
double PeakRssMiB();
