#include "io/resources.hpp"

#include <gtest/gtest.h>
#include <sys/resource.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>

#include "ensemble/cell_summary.hpp"
#include "ensemble/raster_spill.hpp"
#include "test_files.hpp"

namespace talus::io {
namespace {

// 61 x 31 cells of 1 m; 4 releases x 7 rocks; trajectories every 0.1 s, max_time_s 20.
const char* kScene = R"([terrain]
plane = { slope_deg = 35, slope_length_m = 40, runout_m = 20, width_m = 30, cell_m = 1 }
[rock]
shape = { box = [0.5, 0.4, 0.3] }
[release]
points = [[5, 0], [6, 2]]
lines = [[[3, -5], [3, 5]]]
polygons = [[[8, -2], [10, -2], [10, 2], [8, 2]]]
rocks = 7
[solver]
max_time_s = 20
[output]
trajectories = true
trajectory_interval_s = 0.1
rasters = ["speed", "energy", "passages", "reach_probability"]
)";

SceneFile Load(const std::string& text) {
  const auto dir = testing::FreshDir("scene");
  testing::WriteText(dir / "scene.toml", text);
  return LoadScene((dir / "scene.toml").string());
}

const ResourceTerm* Find(const std::vector<ResourceTerm>& terms, const std::string& start) {
  const auto it = std::find_if(terms.begin(), terms.end(),
                               [&](const ResourceTerm& t) { return t.what.rfind(start, 0) == 0; });
  return it == terms.end() ? nullptr : &*it;
}

#define EXPECT_HAS(text, part) EXPECT_NE(std::string(text).find(part), std::string::npos) << (text)

TEST(PercentileStorageBytes, ASummaryPerPassedCellAndAFixedSpillWhateverTheRocks) {
  // A slot and a passage count (4 bytes each) per DEM cell; per statistic and passed cell a
  // ValueSummary with half again of spare capacity; the spill's write buffers and the values it
  // reads back at a time.
  const double summary = sizeof(ensemble::ValueSummary) * 1.5;
  const double spill = ensemble::RasterSpill::kMaxBands * ensemble::RasterSpill::kBufferBytes +
                       ensemble::RasterSpillOptions{}.memory_bytes;
  EXPECT_DOUBLE_EQ(PercentileStorageBytes(1, 100, 1000), 100 * 8 + 100 * summary + spill);
  EXPECT_DOUBLE_EQ(PercentileStorageBytes(1, 100, 10), 100 * 8 + 10 * summary + spill);
  // However many rocks pass, the memory is that of every cell passed.
  EXPECT_DOUBLE_EQ(PercentileStorageBytes(1, 100, 1e9), PercentileStorageBytes(1, 100, 100));
  EXPECT_DOUBLE_EQ(PercentileStorageBytes(3, 100, 1000) - 100 * 8 - spill,
                   3 * (PercentileStorageBytes(1, 100, 1000) - 100 * 8 - spill));
  EXPECT_DOUBLE_EQ(PercentileStorageBytes(0, 100, 1000), 0);
  // On disk: a cell index and a float per statistic for every passage.
  EXPECT_DOUBLE_EQ(RasterSpillBytes(3, 1000), 1000 * 16.0);
}

TEST(EstimateResources, CountsEachPartFromTheScene) {
  const SceneFile scene = Load(kScene);
  const double cells = 61.0 * 31.0, rocks = 28;
  const ResourceEstimate one = EstimateResources(scene, 1);
  const ResourceTerm* dem = Find(one.memory, "DEM heights (61 x 31 cells)");
  ASSERT_NE(dem, nullptr);
  EXPECT_DOUBLE_EQ(dem->bytes, cells * 8);
  EXPECT_DOUBLE_EQ(one.loaded_bytes, cells * 8);  // no ground raster
  EXPECT_DOUBLE_EQ(one.run_bytes(), one.memory_bytes() - cells * 8);
  // Speed and energy: each rock assumed to cross the DEM's diagonal.
  const ResourceTerm* p95 =
      Find(one.memory, "per-cell summaries behind the speed, energy or jump_height rasters");
  ASSERT_NE(p95, nullptr);
  EXPECT_DOUBLE_EQ(p95->bytes, PercentileStorageBytes(2, cells, rocks * std::hypot(61.0, 31.0)));
  EXPECT_HAS(p95->knob, "a coarser DEM");
  // Their percentiles' values spilled to disk: a cell index and two floats per passage.
  const ResourceTerm* spill = Find(one.disk, "values behind the percentile rasters");
  ASSERT_NE(spill, nullptr);
  EXPECT_DOUBLE_EQ(spill->bytes, RasterSpillBytes(2, rocks * std::hypot(61.0, 31.0)));
  EXPECT_HAS(spill->knob, "fewer rocks (--rocks)");
  // Each thread keeps a footprint grid of an int per cell.
  const ResourceEstimate four = EstimateResources(scene, 4);
  EXPECT_DOUBLE_EQ(Find(four.memory, "raster footprint grids of 4 threads")->bytes, 4 * cells * 4);
  EXPECT_GT(four.memory_bytes(), one.memory_bytes());
  // trajectories.h5: 20 s (max_time_s, shorter than the assumed travel) every 0.1 s.
  const ResourceTerm* h5 =
      Find(one.disk, "trajectories.h5 (202 samples per rock: 20 s every 0.1 s)");
  ASSERT_NE(h5, nullptr);
  EXPECT_HAS(h5->knob, "trajectories = false");
  ASSERT_NE(Find(one.disk, "rocks.csv"), nullptr);
  // 8 rasters: max, mean and p95 of speed and energy, passages, reach probability.
  EXPECT_DOUBLE_EQ(Find(one.disk, "GeoTIFFs (8)")->bytes, cells * 8 * 4);

  // No raster, no trajectory: no raster work and no trajectories.h5.
  std::string lean = kScene;
  lean.replace(lean.find("trajectories = true"), 19, "trajectories = false");
  lean.replace(lean.find("rasters = ["), std::string::npos,
               "quicklook = false\ngeopackage = false\n");
  const ResourceEstimate bare = EstimateResources(Load(lean), 1);
  EXPECT_EQ(Find(bare.memory, "raster"), nullptr);
  EXPECT_EQ(Find(bare.memory, "values behind"), nullptr);
  EXPECT_EQ(Find(bare.memory, "quick-look"), nullptr);
  EXPECT_EQ(Find(bare.disk, "trajectories.h5"), nullptr);
  EXPECT_EQ(Find(bare.disk, "rocks.gpkg"), nullptr);  // asked off

  // rocks.gpkg (on by default): a row per rock and, with trajectories, a vertex per sample.
  const std::string gis = kScene;
  const ResourceEstimate with_gpkg = EstimateResources(Load(gis), 1);
  const ResourceTerm* gpkg = Find(with_gpkg.disk, "rocks.gpkg");
  ASSERT_NE(gpkg, nullptr);
  EXPECT_DOUBLE_EQ(gpkg->bytes, rocks * (700 + 202 * 24));
  EXPECT_HAS(gpkg->knob, "geopackage = false");
  EXPECT_EQ(Find(with_gpkg.disk, "evaluation_lines.csv"), nullptr);  // no lines, no line work

  // Evaluation lines: at most a row per rock and line, 150 bytes each, and four doubles per row
  // (with the vectors' growth) for the summary.
  const ResourceEstimate with_lines = EstimateResources(
      Load(gis + "[evaluation_lines]\nlines = [[[20, -10], [20, 10]], [[30, -10], [30, 10]]]\n"),
      1);
  const ResourceTerm* csv = Find(with_lines.disk, "evaluation_lines.csv");
  ASSERT_NE(csv, nullptr);
  EXPECT_DOUBLE_EQ(csv->bytes, rocks * 2 * 150);
  EXPECT_HAS(csv->knob, "fewer evaluation lines");
  const ResourceTerm* values = Find(with_lines.memory, "evaluation line values");
  ASSERT_NE(values, nullptr);
  EXPECT_DOUBLE_EQ(values->bytes, rocks * 2 * 32 * 1.5);
  EXPECT_NE(Find(with_lines.disk, "rocks.gpkg evaluation_crossings"), nullptr);
}

// A run whose estimate exceeds what the machine has is refused with the estimate, what is
// available and the knobs of the largest parts. The limits are injected: nothing is allocated.
TEST(CheckResources, RefusesARunLargerThanTheMemoryOrDiskWithTheKnob) {
  const ResourceEstimate e = EstimateResources(Load(kScene), 2);
  const double unlimited = std::numeric_limits<double>::infinity();
  EXPECT_EQ(CheckResources(e, {unlimited, unlimited}), "");
  EXPECT_EQ(CheckResources(e, {e.run_bytes(), e.disk_bytes()}), "");  // just fits

  const std::string memory = CheckResources(e, {e.run_bytes() - 1, unlimited});
  EXPECT_HAS(memory, "the run needs about " + FormatBytes(e.run_bytes()) +
                         " of memory besides the " + FormatBytes(e.loaded_bytes) +
                         " of the loaded scene, but " + FormatBytes(e.run_bytes() - 1) +
                         " is available (MemAvailable)");
  EXPECT_HAS(memory, "largest parts: ");
  // The rasters' summaries are bounded by the DEM, whatever the rocks.
  EXPECT_HAS(memory, "per-cell summaries behind the speed, energy or jump_height rasters (2 of "
                     "them) (a coarser DEM");
  EXPECT_EQ(memory.find("(fewer rocks (--rocks)"), std::string::npos);
  EXPECT_HAS(memory, "nothing was run");
  EXPECT_EQ(memory.find('\n'), std::string::npos);

  const std::string disk = CheckResources(e, {unlimited, 1e5});
  EXPECT_HAS(disk, "the outputs need about " + FormatBytes(e.disk_bytes()) +
                       " of disk, but 100 kB is free in the output directory");
  EXPECT_HAS(disk,
             "trajectories.h5 (202 samples per rock: 20 s every 0.1 s) (trajectories = false");
}

TEST(MeasureCapacity, ReadsMemAvailableAndTheFreeSpaceOfTheDirectory) {
  const MachineCapacity c = MeasureCapacity(testing::FreshDir("out").string());
  EXPECT_GT(c.memory_bytes, 0);
  EXPECT_TRUE(std::isfinite(c.memory_bytes));  // Linux has /proc/meminfo
  EXPECT_GT(c.disk_bytes, 0);
  EXPECT_TRUE(std::isfinite(c.disk_bytes));
  EXPECT_TRUE(std::isinf(MeasureCapacity("/no/such/directory").disk_bytes));
}

// The memory of a batch job or container: the limits of the process's own cgroup and of its
// ancestors, cgroup v2 and v1, whichever leaves least (files of the test's own, laid out as
// /proc and /sys/fs/cgroup are). Only MemAvailable and a v2 memory.max at the root were read: under
// an 8 GB job limit a run "fitting" 20 GB failed after 56 s with std::bad_alloc.
TEST(MeasureCapacity, TakesTheSmallestLimitOfTheProcessesCgroupsAndTheirAncestors) {
  const auto dir = testing::FreshDir("cgroups");
  const std::string proc = (dir / "proc").string(), cgroup = (dir / "cgroup").string();
  std::filesystem::create_directories(dir / "proc" / "self");
  testing::WriteText(dir / "proc" / "meminfo",
                     "MemTotal: 64000000 kB\nMemAvailable: 20000000 kB\n");
  const auto write = [&](const std::string& file, const std::string& text) {
    std::filesystem::create_directories((dir / "cgroup" / file).parent_path());
    testing::WriteText(dir / "cgroup" / file, text + "\n");
  };
  const CapacitySources sources{proc, cgroup};
  // cgroup v2: the job's cgroup has no limit, its parent 8 GB with 1 GB in use; the root none.
  testing::WriteText(dir / "proc" / "self" / "cgroup", "0::/jobs/job42\n");
  write("jobs/job42/memory.max", "max");
  write("jobs/job42/memory.current", "300000000");
  write("jobs/memory.max", "8000000000");
  write("jobs/memory.current", "1000000000");
  write("memory.max", "max");
  write("memory.current", "40000000000");
  MachineCapacity c = MeasureCapacity(dir.string(), sources);
  EXPECT_EQ(c.memory_bytes, 7e9);
  EXPECT_EQ(c.memory_source, "the memory.max of cgroup /jobs less its memory.current");
  // The job's own limit, when lower.
  write("jobs/job42/memory.max", "2000000000");
  c = MeasureCapacity(dir.string(), sources);
  EXPECT_EQ(c.memory_bytes, 1.7e9);
  EXPECT_EQ(c.memory_source, "the memory.max of cgroup /jobs/job42 less its memory.current");
  // cgroup v1 (memory among other controllers); its "no limit" is about 2^63.
  testing::WriteText(dir / "proc" / "self" / "cgroup",
                     "4:cpu,memory:/slurm/uid_0/job_7\n1:cpuset:/\n0::/\n");
  write("memory/slurm/uid_0/job_7/memory.limit_in_bytes", "9223372036854771712");
  write("memory/slurm/uid_0/job_7/memory.usage_in_bytes", "100");
  write("memory/slurm/uid_0/memory.limit_in_bytes", "4000000000");
  write("memory/slurm/uid_0/memory.usage_in_bytes", "500000000");
  c = MeasureCapacity(dir.string(), sources);
  EXPECT_EQ(c.memory_bytes, 3.5e9);
  EXPECT_EQ(c.memory_source,
            "the memory.limit_in_bytes of cgroup /slurm/uid_0 less its memory.usage_in_bytes");
  // No limit anywhere: MemAvailable.
  write("memory/slurm/uid_0/memory.limit_in_bytes", "9223372036854771712");
  c = MeasureCapacity(dir.string(), sources);
  EXPECT_EQ(c.memory_bytes, 20000000.0 * 1024);
  EXPECT_EQ(c.memory_source, "MemAvailable");
}

// ulimit -v (RLIMIT_AS): what is left of it beside the address space the process uses already.
// A run of the D9 scene under an 8 GB cap was said to fit in 20.7 GB and died of std::bad_alloc.
TEST(MeasureCapacity, TakesTheAddressSpaceLimitLessWhatIsInUse) {
  rlimit old{};
  ASSERT_EQ(::getrlimit(RLIMIT_AS, &old), 0);
  std::ifstream status("/proc/self/status");
  double vm_kb = 0;
  for (std::string line; std::getline(status, line);)
    if (line.rfind("VmSize:", 0) == 0) vm_kb = std::strtod(line.c_str() + 7, nullptr);
  ASSERT_GT(vm_kb, 0);
  const double cap = vm_kb * 1024 + 3e9;  // 3 GB beyond what is mapped now
  if (old.rlim_max != RLIM_INFINITY && double(old.rlim_max) < cap)
    GTEST_SKIP() << "the hard address-space limit is below " << cap << " bytes";
  const rlimit lowered{static_cast<rlim_t>(cap), old.rlim_max};
  ASSERT_EQ(::setrlimit(RLIMIT_AS, &lowered), 0);
  const MachineCapacity c = MeasureCapacity(testing::FreshDir("rlimit").string());
  ::setrlimit(RLIMIT_AS, &old);
  // Up to what the process mapped between reading VmSize and measuring (a few MB).
  EXPECT_LE(c.memory_bytes, 3e9);
  EXPECT_GT(c.memory_bytes, 2.9e9);
  EXPECT_EQ(c.memory_source, "RLIMIT_AS (ulimit -v) less the address space in use");
}

TEST(FormatBytes, DecimalUnits) {
  EXPECT_EQ(FormatBytes(12), "12 B");
  EXPECT_EQ(FormatBytes(820e3), "820 kB");
  EXPECT_EQ(FormatBytes(1.54e9), "1.5 GB");
  EXPECT_EQ(FormatBytes(std::numeric_limits<double>::infinity()), "an unknown amount");
}

}  // namespace
}  // namespace talus::io
