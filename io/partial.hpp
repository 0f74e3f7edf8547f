#pragma once
// Partial results (docs/cluster.md): `talus simulate SCENE --rock-range A:B` runs rocks A .. B - 1
// of the scene's ensemble and writes, instead of the rasters and summary.json,
//   rocks.csv        the rows of its rocks (with the header),
//   trajectories.h5  their rows, when the scene asks for trajectories,
//   evaluation_lines.csv  their crossings, when the scene has evaluation lines (the summary is
//                    computed from the merged file),
//   partial.bin      the raster accumulator (per-cell summaries and the values spilled for the
//                    percentiles, raster_spill.hpp) and the quick-look's sample paths,
//   partial.json     what the part is (scene, its inputs' hash, seed, range, version, counts)
//                    and the size and checksum (SHA-256) of each of its other files; written
//                    last, so that a directory with a partial.json is a complete part.
// Before merging, each part's files are checked against partial.json (CheckPartFiles): a file
// changed, swapped with another part's or damaged since the part was run is refused, as are rows
// of rocks outside the part's range.
// `talus merge` (and rank 0 of an MPI run) combine parts that tile the ensemble into exactly the
// outputs of a single run.

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <map>
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
  std::string inputs_hash;          // SceneFile::inputs_hash (SHA-256), "inputs_sha256"
  std::uint64_t seed = 0;
  long rocks_per_release = 0;
  std::string solver_preset;  // "fast", "default", "accurate" (the scene's or --preset)
  bool solver_preset_from_command_line = false;  // --preset: it won over the scene's keys
  long total_rocks = 0;
  long first_rock = 0, end_rock = 0;  // rocks [first_rock, end_rock)
  bool trajectories = false;
  ensemble::EnsembleReport counts;  // rocks, ends, raised, steps, threads, wall time
  // The part's other files (rocks.csv, partial.bin, ...) by name: size and SHA-256 (hex).
  struct File {
    std::uint64_t bytes = 0;
    std::string sha256;
  };
  std::map<std::string, File> files;
};

// The paths drawn on the quick-look, by rock.
struct SamplePath {
  long rock = 0;
  std::vector<Eigen::Vector2d> xy_m;
};

// partial.json of a part. `files`: the paths of the part's other files, written already (their
// names, sizes and checksums go into partial.json). Throws std::runtime_error when one cannot be
// read.
std::string PartialJson(const SceneFile& scene, const std::string& version, long first_rock,
                        long end_rock, const ensemble::EnsembleReport& report,
                        const std::vector<std::string>& files);
// Writes partial.bin to `path` (atomically, streaming the spilled values: its size in memory does
// not grow with the rocks): the length of its head, the head (the raster accumulator's state and
// the sample paths), then the raster accumulator's spill. Throws std::runtime_error.
void WritePartialState(const std::string& path, const ensemble::EnsembleReport& report,
                       const std::vector<SamplePath>& paths);

// Reads <dir>/partial.json. Throws InputError naming the directory and the problem.
PartialInfo ReadPartialInfo(const std::string& dir);

// Checks the files of a part against its partial.json: each listed file is there with its size
// and checksum, rocks.csv and partial.bin (and trajectories.h5 when the part has trajectories)
// are listed, rocks.csv holds exactly the part's rocks in order and evaluation_lines.csv only
// crossings of them. Throws InputError naming the file (and line) and what is wrong. `on_bytes`,
// when given, hears how many bytes were checksummed as the files are read (for a progress line:
// files.bytes of partial.json add up to the total).
void CheckPartFiles(const PartialInfo& part,
                    const std::function<void(std::uint64_t)>& on_bytes = {});

// Checks that parts belong to one ensemble (same version, scene inputs, seed, rocks) and that their
// ranges cover it exactly once; returns them sorted by range. Throws InputError naming the parts
// that differ, overlap, or the rocks that no part holds.
std::vector<PartialInfo> CheckPartials(std::vector<PartialInfo> parts);

// Reads <dir>/partial.bin: adds its raster state to *rasters (when the scene asks for rasters;
// created on the first part, spilling as `spill` says) and appends its paths. Throws
// std::runtime_error.
void ReadPartialState(const PartialInfo& part, const ensemble::RasterRequest& request,
                      const ensemble::RasterSpillOptions& spill,
                      std::optional<ensemble::RasterAccumulator>* rasters,
                      std::vector<SamplePath>* paths);

}  // namespace talus::io
