#pragma once
// rocks.csv (docs/scenes.md): one row per rock, streamed, complete or absent.

#include <cstdint>
#include <cstdio>
#include <string>

#include "common/atomic_file.hpp"
#include "ensemble/runner.hpp"
#include "solver/scene.hpp"

namespace talus::io {

// A text field as written to the CSV outputs: quoted when it holds a comma, quote or line break
// (RFC 4180), or begins or ends with a blank.
std::string CsvField(const std::string& text);

class RocksCsvWriter {
 public:
  // Opens a temporary file next to `path` and writes the header. Throws std::runtime_error.
  // `release` names each rock's run and block, `scene` the ground category where it ended; both
  // must outlive the writer.
  RocksCsvWriter(const std::string& path, const Scene& scene, const ensemble::ReleaseSpec& release);
  RocksCsvWriter(const RocksCsvWriter&) = delete;
  RocksCsvWriter& operator=(const RocksCsvWriter&) = delete;

  void Write(const ensemble::RockOutcome& rock);
  void Commit();  // flushes, closes and renames into place

  static const char* Header();

 private:
  AtomicTextFile file_;
  const Scene& scene_;
  const ensemble::ReleaseSpec& release_;
};

}  // namespace talus::io
