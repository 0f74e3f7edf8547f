// Benchmark: memory of the raster statistics of an ensemble on a real scene (default
// cases/tirol), for growing numbers of rocks. Prints, per rock count: wall time of the run, the
// passages, the bytes the accumulator holds in memory (RasterAccumulator::MemoryBytes: grids,
// per-cell summaries, the spill's buffers) and on disk (the spilled values behind the
// percentiles), the time Finish takes to pick the percentiles from the spill, and the process's
// peak resident memory after it. With --check, it also keeps every passage's values (in memory:
// not for the memory figures) and compares every percentile raster with the brute-force
// nearest-rank percentile of each cell.

#include <CLI/CLI.hpp>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <map>
#include <string>
#include <vector>

#include "bench/bench_main.hpp"
#include "ensemble/runner.hpp"
#include "io/scene_file.hpp"

namespace {

// Counts passages (all quantities share them) and, with `keep`, keeps every passage's values
// per cell and quantity.
class PassageCounter : public talus::ensemble::RockSink {
 public:
  explicit PassageCounter(bool keep) : keep_(keep) {}
  void OnRock(const talus::ensemble::RockOutcome& rock) override {
    const talus::ensemble::Footprint& f = rock.footprint;
    passages += static_cast<long>(f.cells.size());
    if (!keep_) return;
    for (std::size_t k = 0; k < f.cells.size(); ++k) {
      auto& cell = values[f.cells[k]];
      cell[0].push_back(f.speed_m_s[k]);
      cell[1].push_back(f.energy_j[k]);
      cell[2].push_back(f.jump_height_m[k]);
    }
  }
  long passages = 0;
  std::map<int, std::array<std::vector<float>, 3>> values;

 private:
  bool keep_;
};

// The cells and percentile rasters whose value is not the brute-force nearest-rank percentile
// (rank ceil(p n / 100) of the cell's finite values, sorted); prints the first few.
long CheckPercentiles(const PassageCounter& counter, const talus::Heightfield& dem,
                      const std::vector<talus::ensemble::RasterLayer>& layers) {
  long compared = 0, differ = 0;
  for (const talus::ensemble::RasterLayer& layer : layers) {
    if (layer.statistic.empty() || layer.statistic[0] != 'p') continue;
    const int percent = std::stoi(layer.statistic.substr(1));
    const std::size_t q = layer.quantity == "speed" ? 0 : layer.quantity == "energy" ? 1 : 2;
    for (const auto& [cell, all] : counter.values) {
      if (std::isnan(dem.z_m[static_cast<std::size_t>(cell)])) continue;  // nodata there
      std::vector<float> v;
      for (float x : all[q])
        if (std::isfinite(x)) v.push_back(x);
      if (v.empty()) continue;
      std::sort(v.begin(), v.end());
      const float exact = v[(static_cast<std::size_t>(percent) * v.size() + 99) / 100 - 1];
      const float got = layer.values[static_cast<std::size_t>(cell)];
      ++compared;
      if (got != exact && differ++ < 5)
        std::printf("  %s cell %d: %.9g, brute force %.9g\n", layer.name.c_str(), cell, got, exact);
    }
  }
  std::printf("  check: %ld cell percentiles compared with brute force, %ld differ\n", compared,
              differ);
  return differ;
}

}  // namespace

int RunBenchmark(int argc, char** argv) {
  CLI::App app{"Memory of the raster statistics for growing numbers of rocks"};
  std::string scene_path = std::string(TALUS_SOURCE_DIR) + "/cases/tirol/scene.toml";
  std::vector<long> counts = {100, 1000, 4000};
  int threads = 0;
  bool check = false;
  app.add_option("--scene", scene_path, "Scene file");
  app.add_flag("--check", check, "Compare every percentile raster with brute force");
  app.add_option("--rocks", counts, "Rock counts (per release) to run")->expected(1, -1);
  app.add_option("--threads", threads, "Threads (0: all cores)");
  CLI11_PARSE(app, argc, argv);

  talus::io::SceneFile scene = talus::io::LoadScene(scene_path);
  const talus::GridGeometry& grid = scene.scene.terrain.heights().grid;
  std::printf("scene %s: %s, %d x %d cells\n", scene_path.c_str(),
              scene.terrain_description.c_str(), grid.nx, grid.ny);
  std::printf("%8s %9s %12s %14s %10s %9s %13s\n", "rocks", "wall_s", "passages", "summaries_MiB",
              "spill_MiB", "finish_s", "peak_rss_MiB");
  for (long rocks : counts) {
    scene.release.rocks_per_release = rocks;
    talus::ensemble::EnsembleOptions options;
    options.threads = threads;
    options.rasters = scene.output.Request(grid);
    options.rasters.speed = options.rasters.energy = options.rasters.jump_height = true;
    options.keep_raster_state = true;
    PassageCounter counter(check);
    const auto t0 = std::chrono::steady_clock::now();
    talus::ensemble::EnsembleReport report =
        talus::ensemble::RunEnsemble(scene.scene, scene.release, options, &counter);
    const auto t1 = std::chrono::steady_clock::now();
    const double memory = double(report.raster_state->MemoryBytes());
    const double spill = double(report.raster_state->SpillBytes());
    const std::vector<talus::ensemble::RasterLayer> layers =
        report.raster_state->Finish(scene.scene.terrain.heights());
    const auto t2 = std::chrono::steady_clock::now();
    std::printf("%8ld %9.2f %12ld %14.2f %10.2f %9.2f %13.1f\n", report.rocks,
                std::chrono::duration<double>(t1 - t0).count(), counter.passages,
                memory / (1 << 20), spill / (1 << 20),
                std::chrono::duration<double>(t2 - t1).count(), PeakRssMiB());
    if (check && CheckPercentiles(counter, scene.scene.terrain.heights(), layers) > 0) return 1;
    std::fflush(stdout);
  }
  return 0;
}
