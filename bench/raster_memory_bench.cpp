// Benchmark: memory of the raster statistics of an ensemble on a real scene (default
// cases/tirol), for growing numbers of rocks. Prints, per rock count: wall time, the bytes the
// per-cell summaries hold (RasterAccumulator::MemoryBytes, measured), the bytes the layout they
// replaced would hold for the same footprints (every passing rock's float per cell and quantity
// plus a std::vector per cell and quantity: computed from the passages, not run), the largest
// histogram of a cell, and the process's peak resident memory.

#include <sys/resource.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <exception>
#include <string>

#include "bench/bench_main.hpp"
#include "ensemble/runner.hpp"
#include "io/scene_file.hpp"

namespace {

double PeakRssMiB() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_maxrss) / 1024.0;  // kB on Linux
}

// Counts passages per cell (all quantities share them) to size the replaced layout.
class PassageCounter : public talus::ensemble::RockSink {
 public:
  void OnRock(const talus::ensemble::RockOutcome& rock) override {
    passages += static_cast<long>(rock.footprint.cells.size());
  }
  long passages = 0;
};

}  // namespace

int RunBenchmark(int argc, char** argv) {
  CLI::App app{"Memory of the raster statistics for growing numbers of rocks"};
  std::string scene_path = std::string(TALUS_SOURCE_DIR) + "/cases/tirol/scene.toml";
  std::vector<long> counts = {100, 1000, 4000};
  int threads = 0;
  app.add_option("--scene", scene_path, "Scene file");
  app.add_option("--rocks", counts, "Rock counts (per release) to run")->expected(1, -1);
  app.add_option("--threads", threads, "Threads (0: all cores)");
  CLI11_PARSE(app, argc, argv);

  talus::io::SceneFile scene = talus::io::LoadScene(scene_path);
  const talus::GridGeometry& grid = scene.scene.terrain.heights().grid;
  std::printf("scene %s: %s, %d x %d cells\n", scene_path.c_str(),
              scene.terrain_description.c_str(), grid.nx, grid.ny);
  std::printf("%8s %9s %12s %14s %16s %13s\n", "rocks", "wall_s", "passages", "summaries_MiB",
              "per_rock_MiB(*)", "peak_rss_MiB");
  for (long rocks : counts) {
    scene.release.rocks_per_release = rocks;
    talus::ensemble::EnsembleOptions options;
    options.threads = threads;
    options.rasters = scene.output.Request(grid);
    options.rasters.speed = options.rasters.energy = options.rasters.jump_height = true;
    options.keep_raster_state = true;
    PassageCounter counter;
    const auto t0 = std::chrono::steady_clock::now();
    const talus::ensemble::EnsembleReport report =
        talus::ensemble::RunEnsemble(scene.scene, scene.release, options, &counter);
    const double wall =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const double cells = double(grid.nx) * grid.ny;
    // The replaced layout: per cell max (float), sum (double) and a std::vector<float> of values
    // for each of 3 quantities, plus 4 bytes per passage and quantity, plus the passage and
    // deposit grids.
    const double replaced =
        cells * 3 * (4 + 8 + 24) + 3.0 * 4 * double(counter.passages) + cells * 2 * 4;
    std::printf("%8ld %9.2f %12ld %14.2f %16.2f %13.1f\n", report.rocks, wall, counter.passages,
                double(report.raster_state->MemoryBytes()) / (1 << 20), replaced / (1 << 20),
                PeakRssMiB());
    std::fflush(stdout);
  }
  std::printf(
      "(*) computed for the layout the summaries replaced (every passing rock's value per "
      "cell), without std::vector's spare capacity\n");
  return 0;
}
