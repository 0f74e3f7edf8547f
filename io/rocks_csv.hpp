#pragma once
// rocks.csv (docs/scenes.md): one row per rock, streamed, complete or absent.

#include <cstdint>
#include <cstdio>
#include <string>

#include "common/atomic_file.hpp"
#include "ensemble/runner.hpp"

namespace talus::io {

class RocksCsvWriter {
 public:
  // Opens a temporary file next to `path` and writes the header. Throws std::runtime_error.
  RocksCsvWriter(const std::string& path, std::uint64_t seed);
  ~RocksCsvWriter();
  RocksCsvWriter(const RocksCsvWriter&) = delete;
  RocksCsvWriter& operator=(const RocksCsvWriter&) = delete;

  void Write(const ensemble::RockOutcome& rock);
  void Commit();  // flushes, closes and renames into place

  static const char* Header();

 private:
  AtomicFile file_;
  std::FILE* out_ = nullptr;
  std::uint64_t seed_;
};

}  // namespace talus::io
