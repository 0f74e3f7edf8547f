#pragma once
// Partial results (docs/cluster.md): `talus simulate SCENE --rock-range A:B` runs rocks A .. B - 1
// of the scene's ensemble and writes, instead of the rasters and summary.json,
//   rocks.csv        the rows of its rocks (with the header),
//   trajectories.h5  their rows, when the scene asks for trajectories,
//   evaluation_lines.csv  their crossings, when the scene has evaluation lines (the summary is
//                    computed from the merged file),
//   partial.bin      the raster accumulator (per-cell summaries) and the quick-look's sample paths,
//   partial.json     what the part is (scene, its inputs' hash, seed, range, version, counts);
//                    written last, so that a directory with a partial.json is a complete part.
// `talus merge` (and rank 0 of an MPI run) combine parts that tile the ensemble into exactly the
// outputs of a single run.

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "ensemble/runner.hpp"
#include "io/scene_file.hpp"

namespace talus::io {

// What partial.json says about a part.
struct PartialInfo {
  std::string dir;                  // where it was read from
  std::string version;              // of talus
  std::string scene;                // the scene path as given to talus simulate
  std::string scene_file;           // the same, absolute
  std::vector<std::string> inputs;  // SceneFile::inputs as given
  std::string inputs_hash;
  std::uint64_t seed = 0;
  long rocks_per_release = 0;
  std::string solver_preset;  // "fast", "default", "accurate" (the scene's or --preset)
  bool solver_preset_from_command_line = false;  // --preset: it won over the scene's keys
  long total_rocks = 0;
  long first_rock = 0, end_rock = 0;  // rocks [first_rock, end_rock)
  bool trajectories = false;
  ensemble::EnsembleReport counts;  // rocks, ends, raised, steps, threads, wall time
};

// The paths drawn on the quick-look, by rock.
struct SamplePath {
  long rock = 0;
  std::vector<Eigen::Vector2d> xy_m;
};

// partial.json and partial.bin of a part.
std::string PartialJson(const SceneFile& scene, const std::string& version, long first_rock,
                        long end_rock, const ensemble::EnsembleReport& report);
std::string PartialState(const ensemble::EnsembleReport& report,
                         const std::vector<SamplePath>& paths);

// Reads <dir>/partial.json. Throws InputError naming the directory and the problem.
PartialInfo ReadPartialInfo(const std::string& dir);

// Checks that parts belong to one ensemble (same version, scene inputs, seed, rocks) and that their
// ranges cover it exactly once; returns them sorted by range. Throws InputError naming the parts
// that differ, overlap, or the rocks that no part holds.
std::vector<PartialInfo> CheckPartials(std::vector<PartialInfo> parts);

// Reads <dir>/partial.bin: adds its raster state to *rasters (when the scene asks for rasters;
// created on the first part) and appends its paths. Throws std::runtime_error.
void ReadPartialState(const PartialInfo& part, const ensemble::RasterRequest& request,
                      std::optional<ensemble::RasterAccumulator>* rasters,
                      std::vector<SamplePath>* paths);

}  // namespace talus::io
