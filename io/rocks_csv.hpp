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

// One row of rocks.csv as values (docs/scenes.md names each column).
struct RockRow {
  long rock = 0;
  int release = 0;
  std::string run;  // the release's name
  std::uint64_t seed = 0;
  const char* end = "";  // ToString(EndReason)
  double x_end = 0, y_end = 0, z_end = 0;
  double runout_m = 0, path_length_m = 0, travel_time_s = 0, max_speed_m_s = 0;
  double max_kinetic_energy_j = 0, max_jump_height_m = 0, max_angular_speed_rad_s = 0;
  double max_scar_m = 0;
  std::string block;  // the run's block; "" without
  double mass_kg = 0;
  double x_start = 0, y_start = 0, z_start = 0;
  double travel_angle_deg = 0;  // of the centre of mass, release to end (Fahrboeschung)
  std::string end_ground;       // the ground category where it ended
  std::string end_barrier;      // the barrier that stopped it (ending "barrier"); "" otherwise
};

// The row of `rock`; `scene` and `release` are those it ran with.
RockRow RockRowOf(const ensemble::RockOutcome& rock, const Scene& scene,
                  const ensemble::ReleaseSpec& release);

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
