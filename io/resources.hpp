#pragma once
// What a run of a scene will need in memory and on disk, estimated before any rock runs, and the
// check of that estimate against what the machine has (MemAvailable, free space of the output
// directory), so that a run too large fails at once with the estimate and the knob to turn
// instead of dying hours later with std::bad_alloc or a full disk.

#include <string>
#include <vector>

#include "io/scene_file.hpp"

namespace talus::io {

// One part of an estimate: what it is, its size and what makes it smaller.
struct ResourceTerm {
  std::string what;  // e.g. "DEM heights (270 x 370 cells)"
  double bytes = 0;
  std::string knob;  // e.g. "a coarser DEM"
};

struct ResourceEstimate {
  std::vector<ResourceTerm> memory;  // the loaded scene and what the run allocates
  std::vector<ResourceTerm> disk;    // the output files
  double loaded_bytes = 0;           // the part of memory_bytes() held already (the scene)
  double memory_bytes() const;
  double disk_bytes() const;
  // The run's own allocations: what must still fit in the available memory.
  double run_bytes() const { return memory_bytes() - loaded_bytes; }
};

// Estimates the run of `scene` on `threads` worker threads (resolved: >= 1), with the outputs
// its [output] table asks for. Counts the DEM and ground grid, each thread's raster footprint
// grid, the raster accumulators, the per-cell storage of the percentile rasters, the finished rocks
// waiting to be written, the quick-look image, and trajectories.h5, rocks.csv, the GeoTIFFs and
// the values spilled for the percentile rasters.
// Where the size depends on how far and long rocks travel, it assumes that each rock crosses the
// DEM along its diagonal and travels kAssumedTravelTime_s (or max_time_s when shorter).
ResourceEstimate EstimateResources(const SceneFile& scene, int threads);

// How long a rock is assumed to travel, for the trajectory samples (cases/tirol: 78.6 s on
// average with max_time_s = 120; io/resources.cpp has the measured sizes behind the estimate).
inline constexpr double kAssumedTravelTime_s = 100;

// Bytes of memory behind the speed, energy and jump height rasters for `stats` statistics (0 to
// 3) on `cells` raster cells, holding `passes` (rock, cell) values in all: bounded by the cells,
// whatever the rocks. RasterSpillBytes: the disk the values behind their percentiles take during
// the run. The one place that knows how RasterAccumulator keeps them.
double PercentileStorageBytes(int stats, double cells, double passes);
double RasterSpillBytes(int stats, double passes);

// What the machine offers the run.
struct MachineCapacity {
  double memory_bytes = 0;  // the smallest of the memory limits below
  double disk_bytes = 0;    // free space of the output directory for unprivileged users
  std::string memory_source = "MemAvailable";  // which limit memory_bytes is
};

// Where MeasureCapacity reads (a test points them at files of its own).
struct CapacitySources {
  std::string proc = "/proc";
  std::string cgroup = "/sys/fs/cgroup";
};

// The memory is the smallest of: MemAvailable (/proc/meminfo); for the process's own cgroup and
// each of its ancestors (/proc/self/cgroup), a cgroup v2 memory.max less memory.current and a
// cgroup v1 memory.limit_in_bytes less memory.usage_in_bytes; RLIMIT_AS (ulimit -v) less the
// address space in use (VmSize) and RLIMIT_DATA less the data in use (VmData). The disk is
// statvfs(out_dir). A value it cannot read is infinite (no refusal on a guess).
MachineCapacity MeasureCapacity(const std::string& out_dir);
MachineCapacity MeasureCapacity(const std::string& out_dir, const CapacitySources& sources);

// "" when the run fits, else one line: the estimate, what is available and the largest terms
// with their knobs.
std::string CheckResources(const ResourceEstimate& estimate, const MachineCapacity& capacity);

// "1.5 GB", "820 kB", "12 B" (decimal units).
std::string FormatBytes(double bytes);

}  // namespace talus::io
