#pragma once
// Each benchmark program defines RunBenchmark; bench_main.cpp's main runs it.

// Parses the command line, runs the benchmark and prints its figures; the exit code.
int RunBenchmark(int argc, char** argv);
