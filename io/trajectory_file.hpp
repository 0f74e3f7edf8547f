#pragma once
// trajectories.h5 (docs/scenes.md): group /rocks/<rock> per rock with datasets t (n),
// position (n x 3), quaternion (n x 4, w x y z, the shape as given), velocity (n x 3),
// angular_velocity (n x 3, world frame), contact (n, 0/1), scar (n); chunked and
// deflate-compressed, written rock by rock (nothing is kept in memory), complete or absent.
// Objects carry no timestamps: the same rocks give the same bytes. Every HDF5 failure (a full
// disk, a file-size limit) is one std::runtime_error naming the file and the reason; HDF5 prints
// nothing itself; a writer that failed writes nothing more and its temporary file goes with it.

#include <memory>
#include <string>
#include <vector>

#include "common/atomic_file.hpp"
#include "ensemble/runner.hpp"
#include "solver/polyhedron.hpp"

namespace talus::io {

// One rock's group of a trajectories.h5, as read back.
struct StoredTrajectory {
  double mass_kg = 0;
  Eigen::Vector3d principal_inertia_kg_m2 = Eigen::Vector3d::Zero();
  std::vector<ensemble::TrajectorySample> samples;
};

class TrajectoryWriter {
 public:
  // Creates the file under a temporary name; root attributes mass_kg and principal_inertia_kg_m2
  // of the scene's rock. Each rock's group carries those of the shape it ran with.
  TrajectoryWriter(const std::string& path, const RockShape& rock);
  ~TrajectoryWriter();
  TrajectoryWriter(const TrajectoryWriter&) = delete;
  TrajectoryWriter& operator=(const TrajectoryWriter&) = delete;

  void Write(const ensemble::RockOutcome& rock);
  // Writes a rock read from another file: the same bytes as Write of the rock it came from.
  void Write(long rock, const StoredTrajectory& trajectory);
  void Commit();  // closes and renames into place

 private:
  struct Impl;
  AtomicFile file_;
  std::unique_ptr<Impl> impl_;
};

// Reads rocks back from a trajectories.h5 (for merging partial runs). Throws std::runtime_error
// naming the file, the rock and the reason.
class TrajectoryReader {
 public:
  explicit TrajectoryReader(const std::string& path);
  ~TrajectoryReader();
  TrajectoryReader(const TrajectoryReader&) = delete;
  TrajectoryReader& operator=(const TrajectoryReader&) = delete;

  StoredTrajectory Read(long rock) const;

 private:
  struct Impl;
  std::string path_;
  std::unique_ptr<Impl> impl_;
};

}  // namespace talus::io
