#include "io/resources.hpp"

#include <sys/resource.h>
#include <sys/statvfs.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <numeric>
#include <optional>
#include <sstream>

#include "ensemble/cell_summary.hpp"
#include "ensemble/ordered_pool.hpp"
#include "ensemble/outcome.hpp"
#include "ensemble/raster_spill.hpp"

namespace talus::io {
namespace {

// Sizes of the output files. trajectories.h5 takes a row of its rock index per rock (56 bytes
// before compression) and a part per sample (121 bytes of values, of which the velocities,
// quaternions and scars are stored plain and the rest deflate-compressed: 92 bytes measured on
// cases/tirol, 108 on the 40 degree ramp, 200 rocks each; bench/README.md, "What a run pays
// besides its rocks"); a row of rocks.csv (148 bytes). GeoTIFFs are counted uncompressed (4 bytes
// per cell), an upper bound.
constexpr double kTrajectoryBytesPerRock = 56;
constexpr double kTrajectoryBytesPerSample = 108;
constexpr double kRocksCsvBytesPerRow = 150;
// A row of evaluation_lines.csv (cases/tirol, two lines: 260 rows, 35 934 bytes, 138 per row).
constexpr double kEvaluationLinesCsvBytesPerRow = 150;
// A row of barriers.csv (cases/tirol/scene_net.toml, 1000 rocks: 371 rows, 60 640 bytes, 163 per
// row; 180 with longer names).
constexpr double kBarriersCsvBytesPerRow = 180;
// tree_impacts.csv (cases/tirol/scene_forest.toml, 1000 rocks through a 30 ha stand of 400
// stems/ha: 16040 rows, 1 906 765 bytes, 119 per row; 16 rows per rock).
constexpr double kTreeImpactsCsvBytesPerRow = 130;
constexpr double kTreeImpactRowsPerRock = 20;
// rocks.gpkg: an end point with its fields and spatial index; a path's vertex (x, y, z) and per
// path its row and index (1000 rocks on a plane: 2.26 MB, 1.46 MB of it path geometry, 61 vertices
// each).
constexpr double kGeoPackageBytesPerRock = 700;
constexpr double kGeoPackageBytesPerVertex = 24;
constexpr double kGeoPackageBytesPerTree = 200;
constexpr double kGeoTiffBytesPerCell = 4;

// The heap's own bytes per allocation (glibc: an 8-byte header, 16-byte granularity), and the
// spare capacity of a std::vector grown by push_back (capacity doubles: 1.5 on average).
constexpr double kHeapBlockOverhead = 16;
constexpr double kVectorGrowth = 1.5;

// The quick-look image per pixel, an upper bound: cairo's 4-byte canvas, the paths' 4-byte layer
// (MapPaths), the 3-byte rows handed to libpng and the encoded PNG (io/quicklook.cpp) come to
// under 14 bytes.
constexpr double kQuickLookBytesPerPixel = 3 * sizeof(double) + 1 + 3;

std::string Cells(const GridGeometry& g) {
  return std::to_string(g.nx) + " x " + std::to_string(g.ny) + " cells";
}

}  // namespace

double PercentileStorageBytes(int stats, double cells, double passes) {
  // RasterAccumulator: a ValueSummary per passed cell and statistic (ensemble/cell_summary.hpp) in
  // one growing vector, a slot per DEM cell pointing at the cell's summaries and a passage count
  // per DEM cell; the spill's write buffers and, at the end, the values it reads back at a time
  // (ensemble/raster_spill.hpp). None of it grows with the rocks beyond one summary per cell.
  if (stats == 0) return 0;
  const double touched = std::min(cells, passes);  // cells with at least one value
  const ensemble::RasterSpillOptions spill;
  return cells * 2 * sizeof(int) +
         stats * touched * sizeof(ensemble::ValueSummary) * kVectorGrowth +
         double(ensemble::RasterSpill::kMaxBands) * ensemble::RasterSpill::kBufferBytes +
         double(spill.memory_bytes);
}

double RasterSpillBytes(int stats, double passes) { return passes * (4.0 + 4.0 * stats); }

double ResourceEstimate::memory_bytes() const {
  return std::accumulate(memory.begin(), memory.end(), 0.0,
                         [](double sum, const ResourceTerm& t) { return sum + t.bytes; });
}

double ResourceEstimate::disk_bytes() const {
  return std::accumulate(disk.begin(), disk.end(), 0.0,
                         [](double sum, const ResourceTerm& t) { return sum + t.bytes; });
}

ResourceEstimate EstimateResources(const SceneFile& scene, int threads) {
  ResourceEstimate e;
  const Terrain& terrain = scene.scene.terrain;
  const GridGeometry& dem = terrain.heights().grid;
  const double cells = double(dem.nx) * double(dem.ny);
  const double rocks = double(scene.release.total_rocks());
  const OutputSpec& output = scene.output;
  const ensemble::RasterRequest rasters = output.Request(dem);

  // The scene, loaded already.
  e.memory.push_back({"DEM heights (" + Cells(dem) + ")", cells * sizeof(double), "a coarser DEM"});
  if (terrain.has_ground_grid()) {
    const GridGeometry& g = terrain.ground_grid().grid;
    e.memory.push_back({"ground raster (" + Cells(g) + ")", double(g.nx) * double(g.ny),
                        "a coarser ground raster"});
  }
  e.loaded_bytes = e.memory_bytes();

  // How far and how long a rock goes (see the header): the DEM's diagonal in cells, and the
  // assumed travel time in trajectory samples.
  const double footprint = std::min(cells, std::hypot(double(dem.nx), double(dem.ny)));
  const double travel_s = std::min(scene.scene.options.max_time_s, kAssumedTravelTime_s);
  const double samples = travel_s / output.trajectory_interval_s + 2;

  const int stats = int(rasters.speed) + int(rasters.energy) + int(rasters.jump_height);
  const std::string fewer_rasters = "fewer rasters in [output] rasters, or a coarser DEM";
  if (rasters.any()) {
    // FootprintRecorder: a slot per cell on every worker thread.
    e.memory.push_back({"raster footprint grids of " + std::to_string(threads) + " threads",
                        double(threads) * cells * sizeof(int),
                        "fewer threads (--threads), or a coarser DEM"});
    // RasterAccumulator: passage and deposit counters per DEM cell.
    const double counters =
        (rasters.passages || rasters.reach_probability ? 1 : 0) + (rasters.deposits ? 1 : 0);
    e.memory.push_back({"raster accumulators", cells * counters * sizeof(int), fewer_rasters});
    if (stats > 0)
      e.memory.push_back(
          {"per-cell summaries behind the speed, energy or jump_height rasters (" +
               std::to_string(stats) + " of them)",
           PercentileStorageBytes(stats, cells, rocks * footprint),
           "a coarser DEM, or leave speed, energy and jump_height out of [output] rasters"});
    if (stats > 0 && !rasters.percentiles.empty())
      e.disk.push_back({"values behind the percentile rasters (spilled during the run, removed "
                        "at its end)",
                        RasterSpillBytes(stats, rocks * footprint),
                        "fewer rocks (--rocks), or no percentiles in [output]"});
    const double layers = (2 + double(rasters.percentiles.size())) * stats + int(rasters.passages) +
                          int(rasters.deposits) + int(rasters.reach_probability);
    e.memory.push_back({"output rasters", cells * layers * sizeof(float), fewer_rasters});
    e.disk.push_back({"GeoTIFFs (" + std::to_string(int(layers)) + ")",
                      cells * layers * kGeoTiffBytesPerCell, fewer_rasters});
  }
  // Finished rocks wait in the ordered pool's window (and one runs on each thread).
  const double in_flight = double(ensemble::OrderedPoolWindow(threads) + threads);
  double rock_bytes = sizeof(ensemble::RockOutcome) + footprint * (sizeof(int) + stats * 4.0);
  if (output.trajectories) rock_bytes += samples * sizeof(ensemble::TrajectorySample);
  e.memory.push_back({"finished rocks waiting to be written", in_flight * rock_bytes,
                      output.trajectories ? "fewer threads (--threads), or a larger "
                                            "trajectory_interval_s"
                                          : "fewer threads (--threads)"});
  if (output.quicklook) {
    const int scale = std::max(1, 900 / std::max(dem.nx, dem.ny));  // as WriteQuickLookPng draws
    e.memory.push_back({"quick-look image", cells * scale * scale * kQuickLookBytesPerPixel,
                        "quicklook = false in [output], or a coarser DEM"});
  }

  e.disk.push_back({"rocks.csv", rocks * kRocksCsvBytesPerRow, "fewer rocks (--rocks)"});
  if (!scene.evaluation_lines.empty()) {
    // At most a row per rock and line (every rock crossing every line); the summary holds four
    // numbers per row while it reads them back (io/evaluation_lines_csv.hpp).
    const double rows = rocks * double(scene.evaluation_lines.size());
    const char* fewer = "fewer rocks (--rocks) or fewer evaluation lines";
    e.disk.push_back({"evaluation_lines.csv", rows * kEvaluationLinesCsvBytesPerRow, fewer});
    e.memory.push_back({"evaluation line values behind the summary",
                        rows * 4 * sizeof(double) * kVectorGrowth, fewer});
    if (output.geopackage)
      e.disk.push_back({"rocks.gpkg evaluation_crossings", rows * kGeoPackageBytesPerRock, fewer});
  }
  if (!scene.scene.barriers.empty()) {
    // At most a row per rock and barrier; the summary holds three numbers per row.
    const double rows = rocks * double(scene.scene.barriers.size());
    const char* fewer = "fewer rocks (--rocks) or fewer barriers";
    e.disk.push_back({"barriers.csv", rows * kBarriersCsvBytesPerRow, fewer});
    e.memory.push_back(
        {"barrier values behind the summary", rows * 3 * sizeof(double) * kVectorGrowth, fewer});
    if (output.geopackage)
      e.disk.push_back({"rocks.gpkg barrier_impacts", rows * kGeoPackageBytesPerRock, fewer});
  }
  if (scene.has_forest) {
    // Rows per rock: the stems it touches, which depends on the forest; tirol's dense stand as
    // the estimate. The summary reads the file back in rows of a few numbers.
    const double rows = rocks * kTreeImpactRowsPerRock;
    const char* fewer = "fewer rocks (--rocks)";
    e.disk.push_back({"tree_impacts.csv", rows * kTreeImpactsCsvBytesPerRow, fewer});
    e.memory.push_back(
        {"tree impacts behind the summary", rows * kTreeImpactsCsvBytesPerRow * 4, fewer});
    // The stems (position, DBH, foot, capacity) and their look-up grid's index.
    const double stems = double(scene.scene.forest.stems().size());
    e.memory.push_back({"forest", stems * (sizeof(Stem) + sizeof(double) + 2 * sizeof(int)),
                        "a sparser or smaller [forest]"});
    // rocks.gpkg's trees layer: a point of 7 fields per stem with its index entries.
    if (output.geopackage)
      e.disk.push_back(
          {"rocks.gpkg trees", stems * kGeoPackageBytesPerTree, "a sparser or smaller [forest]"});
  }
  if (!scene.scene.forest_drag.empty()) {
    // The forest as a drag layer: one stand index per DEM node, and the stands.
    const ForestDrag& drag = scene.scene.forest_drag;
    e.memory.push_back({"forest drag layer",
                        double(drag.cells().size()) * sizeof(int) +
                            double(drag.stands().size()) * sizeof(DragStand),
                        "a coarser DEM"});
  }
  if (output.geopackage)
    e.disk.push_back({"rocks.gpkg",
                      rocks * (kGeoPackageBytesPerRock +
                               (output.trajectories ? samples * kGeoPackageBytesPerVertex : 0.0)),
                      "geopackage = false in [output], or fewer rocks (--rocks)"});
  if (output.trajectories) {
    char what[160];
    std::snprintf(what, sizeof what, "trajectories.h5 (%.0f samples per rock: %.0f s every %g s)",
                  samples, travel_s, output.trajectory_interval_s);
    e.disk.push_back(
        {what, rocks * (kTrajectoryBytesPerRock + samples * kTrajectoryBytesPerSample),
         "trajectories = false or a larger trajectory_interval_s in [output], or fewer rocks "
         "(--rocks)"});
  }
  return e;
}

namespace {

// The first word of a file as a number of bytes; nullopt when it cannot be read or is "max".
std::optional<double> ReadBytes(const std::string& path) {
  std::ifstream in(path);
  std::string word;
  if (!(in >> word) || word == "max") return std::nullopt;
  char* end = nullptr;
  const double v = std::strtod(word.c_str(), &end);
  if (end == word.c_str() || !(v >= 0)) return std::nullopt;
  return v;
}

// "<key>: <n> kB" of a /proc file (meminfo, self/status) in bytes.
std::optional<double> ReadProcKb(const std::string& path, const std::string& key) {
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line))
    if (line.compare(0, key.size() + 1, key + ":") == 0) {
      const double kb = std::strtod(line.c_str() + key.size() + 1, nullptr);
      return kb * 1024;
    }
  return std::nullopt;
}

// The cgroup `path` ("/a/b") and each of its ancestors up to the root, inner first.
std::vector<std::string> CgroupChain(std::string path) {
  std::vector<std::string> chain;
  while (!path.empty() && path.back() == '/') path.pop_back();
  for (;;) {
    chain.push_back(path.empty() ? "/" : path);
    if (path.empty()) break;
    path.erase(path.rfind('/'));
  }
  return chain;
}

}  // namespace

MachineCapacity MeasureCapacity(const std::string& out_dir) {
  return MeasureCapacity(out_dir, CapacitySources{});
}

MachineCapacity MeasureCapacity(const std::string& out_dir, const CapacitySources& sources) {
  constexpr double kUnknown = std::numeric_limits<double>::infinity();
  MachineCapacity c;
  c.memory_bytes = kUnknown;
  c.disk_bytes = kUnknown;
  if (const auto available = ReadProcKb(sources.proc + "/meminfo", "MemAvailable"))
    c.memory_bytes = *available;
  const auto lower = [&c](double left, const std::string& source) {
    if (left < c.memory_bytes) {
      c.memory_bytes = std::max(0.0, left);
      c.memory_source = source;
    }
  };
  // The limits of the process's own cgroup and of its ancestors (a batch job's, a container's):
  // cgroup v2 (memory.max, at the unified mount or below "unified" in a hybrid layout) and v1
  // (the memory controller's memory.limit_in_bytes; its "no limit" is about 2^63).
  std::ifstream cgroups(sources.proc + "/self/cgroup");
  for (std::string line; std::getline(cgroups, line);) {
    const std::size_t first = line.find(':'), second = line.find(':', first + 1);
    if (first == std::string::npos || second == std::string::npos) continue;
    const std::string controllers = line.substr(first + 1, second - first - 1);
    const std::string path = line.substr(second + 1);
    if (line.compare(0, first, "0") == 0 && controllers.empty()) {
      for (const std::string& dir : CgroupChain(path))
        for (const char* mount : {"", "/unified"}) {
          const std::string base = sources.cgroup + mount + (dir == "/" ? "" : dir);
          const auto max = ReadBytes(base + "/memory.max");
          const auto current = ReadBytes(base + "/memory.current");
          if (max && current)
            lower(*max - *current, "the memory.max of cgroup " + dir + " less its memory.current");
        }
    } else if (("," + controllers + ",").find(",memory,") != std::string::npos) {
      for (const std::string& dir : CgroupChain(path)) {
        const std::string base = sources.cgroup + "/memory" + (dir == "/" ? "" : dir);
        const auto limit = ReadBytes(base + "/memory.limit_in_bytes");
        const auto usage = ReadBytes(base + "/memory.usage_in_bytes");
        if (limit && usage && *limit < 0x1p62)
          lower(*limit - *usage,
                "the memory.limit_in_bytes of cgroup " + dir + " less its memory.usage_in_bytes");
      }
    }
  }
  // The process's own limits (ulimit -v, ulimit -d) less what it uses of them already.
  rlimit limit{};
  if (::getrlimit(RLIMIT_AS, &limit) == 0 && limit.rlim_cur != RLIM_INFINITY)
    if (const auto used = ReadProcKb(sources.proc + "/self/status", "VmSize"))
      lower(double(limit.rlim_cur) - *used, "RLIMIT_AS (ulimit -v) less the address space in use");
  if (::getrlimit(RLIMIT_DATA, &limit) == 0 && limit.rlim_cur != RLIM_INFINITY)
    if (const auto used = ReadProcKb(sources.proc + "/self/status", "VmData"))
      lower(double(limit.rlim_cur) - *used, "RLIMIT_DATA (ulimit -d) less the data in use");
  struct statvfs fs {};
  if (::statvfs(out_dir.c_str(), &fs) == 0)
    c.disk_bytes = double(fs.f_bavail) * double(fs.f_frsize);
  return c;
}

namespace {

// "<size> <what> (<knob>)" for the largest terms, up to three.
std::string LargestTerms(std::vector<ResourceTerm> terms) {
  std::stable_sort(terms.begin(), terms.end(),
                   [](const ResourceTerm& a, const ResourceTerm& b) { return a.bytes > b.bytes; });
  std::string out;
  for (std::size_t k = 0; k < std::min<std::size_t>(3, terms.size()); ++k) {
    if (terms[k].bytes <= 0) break;
    out += (k ? "; " : "") + FormatBytes(terms[k].bytes) + " " + terms[k].what + " (" +
           terms[k].knob + ")";
  }
  return out;
}

}  // namespace

std::string CheckResources(const ResourceEstimate& estimate, const MachineCapacity& capacity) {
  if (estimate.run_bytes() > capacity.memory_bytes) {
    return "the run needs about " + FormatBytes(estimate.run_bytes()) + " of memory besides the " +
           FormatBytes(estimate.loaded_bytes) + " of the loaded scene, but " +
           FormatBytes(capacity.memory_bytes) + " is available (" + capacity.memory_source +
           "); largest parts: " + LargestTerms(estimate.memory) + "; nothing was run";
  }
  if (estimate.disk_bytes() > capacity.disk_bytes)
    return "the outputs need about " + FormatBytes(estimate.disk_bytes()) + " of disk, but " +
           FormatBytes(capacity.disk_bytes) +
           " is free in the output directory; largest parts: " + LargestTerms(estimate.disk) +
           "; nothing was run";
  return "";
}

std::string FormatBytes(double bytes) {
  if (!std::isfinite(bytes)) return "an unknown amount";
  const char* units[] = {"B", "kB", "MB", "GB", "TB", "PB"};
  int u = 0;
  while (bytes >= 1000 && u < 5) {
    bytes /= 1000;
    ++u;
  }
  char text[32];
  std::snprintf(text, sizeof text, u == 0 || bytes >= 100 ? "%.0f %s" : "%.1f %s", bytes, units[u]);
  return text;
}

}  // namespace talus::io
