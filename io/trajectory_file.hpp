#pragma once
// trajectories.h5 (docs/scenes.md "Outputs"): one table per quantity over the samples of all rocks,
// rock after rock, and an index with one row per rock:
//   /samples/t (n), position (n x 3), quaternion (n x 4, w x y z, the shape as given),
//            velocity (n x 3), angular_velocity (n x 3, world frame), contact (n, 0/1), scar (n)
//   /rocks/rock (r), first_sample (r), sample_count (r), mass_kg (r),
//          principal_inertia_kg_m2 (r x 3)
// Every dataset has string attributes `units` and `frame` ("world", "body" or "none"); the root
// has `format`, `format_version`, `crs` (the DEM's WKT, or "local metres") and the scene rock's
// mass_kg and principal_inertia_kg_m2. Tables are chunked (8192 rows), written a chunk at a time
// (memory does not grow with the rocks), complete or absent; all but velocity, quaternion and scar
// are shuffled and deflate-compressed. Objects carry no timestamps and the bytes depend on the rocks alone: the same rocks give
// the same bytes, however they were split. Every HDF5 failure (a full disk, a file-size limit) is
// one std::runtime_error naming the file and the reason; HDF5 prints nothing itself; a writer that
// failed writes nothing more and its temporary file goes with it.

#include <memory>
#include <string>
#include <vector>

#include "common/atomic_file.hpp"
#include "ensemble/runner.hpp"
#include "solver/polyhedron.hpp"

namespace talus::io {

inline constexpr const char* kTrajectoryFormat = "talus trajectories";
inline constexpr int kTrajectoryFormatVersion = 2;        // 1: a group per rock (/rocks/<rock>/...)
inline constexpr const char* kLocalCrs = "local metres";  // the crs of a scene without one

// One rock of a trajectories.h5, as read back.
struct StoredTrajectory {
  double mass_kg = 0;
  Eigen::Vector3d principal_inertia_kg_m2 = Eigen::Vector3d::Zero();
  std::vector<ensemble::TrajectorySample> samples;
};

class TrajectoryWriter {
 public:
  // Creates the file under a temporary name; root attributes mass_kg and principal_inertia_kg_m2
  // of the scene's rock and `crs` (`crs_wkt`, or kLocalCrs when empty). Each rock's row carries
  // those of the shape it ran with.
  TrajectoryWriter(const std::string& path, const RockShape& rock, const std::string& crs_wkt);
  ~TrajectoryWriter();
  TrajectoryWriter(const TrajectoryWriter&) = delete;
  TrajectoryWriter& operator=(const TrajectoryWriter&) = delete;

  // Rocks come in increasing order (else std::logic_error).
  void Write(const ensemble::RockOutcome& rock);
  // Writes a rock read from another file: the same bytes as Write of the rock it came from.
  void Write(long rock, const StoredTrajectory& stored);
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

  // One rock: its index row, then its rows of the sample tables (rocks read in order share the
  // index and sample chunks HDF5 caches).
  StoredTrajectory Read(long rock) const;
  long rocks() const;  // rows of the index

 private:
  struct Impl;
  std::string path_;
  std::unique_ptr<Impl> impl_;
};

}  // namespace talus::io
