// talus simulate: run a scene's ensemble and write rocks.csv, rasters, trajectories and a summary.

#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>
#include <string>

#include "app/commands.hpp"
#include "common/atomic_file.hpp"
#include "common/error.hpp"
#include "ensemble/runner.hpp"
#include "io/quicklook.hpp"
#include "io/raster.hpp"
#include "io/rocks_csv.hpp"
#include "io/scene_file.hpp"
#include "io/summary.hpp"
#include "io/trajectory_file.hpp"
#include "talus/version.hpp"

namespace talus::app {
namespace {

// "rock <shape> (<mass> kg, <n> hull vertices); <k> releases x <n> rocks, seed <s>", or the runs
// and blocks of a run table.
std::string DescribeRocks(const io::SceneFile& scene) {
  const ensemble::ReleaseSpec& r = scene.release;
  char line[512];
  if (!r.runs.empty()) {
    std::snprintf(line, sizeof line, "%zu runs x %ld rocks, %zu blocks%s, seed %llu", r.runs.size(),
                  r.rocks_per_release, r.blocks.size(),
                  r.shape_per_rock ? " (a shape of its own per rock)" : "",
                  static_cast<unsigned long long>(r.seed));
  } else {
    std::snprintf(line, sizeof line,
                  "rock %s (%.1f kg, %zu hull vertices)%s; %zu releases x %ld rocks, seed %llu",
                  scene.rock_description.c_str(), scene.scene.rock.mass_kg,
                  scene.scene.rock.vertices_m.size(),
                  r.shape_per_rock ? ", a shape of its own per rock" : "", r.releases.size(),
                  r.rocks_per_release, static_cast<unsigned long long>(r.seed));
  }
  return line;
}

struct SimulateArgs {
  std::string scene;
  std::string out;
  long rocks = 0;  // per release; 0: the scene's
  int threads = 0;
  std::optional<std::uint64_t> seed;
};

// Streams each finished rock to rocks.csv and trajectories.h5.
// Keeps the horizontal paths of the quick-look's sample rocks.
class FileSink : public ensemble::RockSink {
 public:
  FileSink(io::RocksCsvWriter& csv, io::TrajectoryWriter* trajectories, long sample)
      : csv_(csv), trajectories_(trajectories), sample_(sample) {}
  void OnRock(const ensemble::RockOutcome& rock) override {
    csv_.Write(rock);
    if (trajectories_) trajectories_->Write(rock);
    if (rock.rock < sample_) {
      std::vector<Eigen::Vector2d>& path = paths.emplace_back();
      for (const ensemble::TrajectorySample& s : rock.trajectory)
        path.push_back(s.position_m.head<2>());
    }
  }
  std::vector<std::vector<Eigen::Vector2d>> paths;

 private:
  io::RocksCsvWriter& csv_;
  io::TrajectoryWriter* trajectories_;
  long sample_;
};

constexpr long kQuickLookPaths = 20;  // rocks drawn on the quick-look

// "rocks done / total, rate, time left" on a terminal; nothing otherwise.
class ProgressBar {
 public:
  ProgressBar()
      : enabled_(::isatty(STDERR_FILENO) != 0), start_(std::chrono::steady_clock::now()) {}
  void operator()(long done, long total) {
    if (!enabled_ || total <= 0) return;
    const double elapsed =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    const double rate = elapsed > 0 ? double(done) / elapsed : 0.0;
    const double left = rate > 0 ? double(total - done) / rate : 0.0;
    constexpr int kWidth = 30;
    const int filled = static_cast<int>(kWidth * done / total);
    std::fprintf(stderr, "\r[%-*.*s] %ld/%ld rocks  %.1f/s  %s left   ", kWidth, filled,
                 "##############################", done, total, rate,
                 done > 0 ? (std::to_string(static_cast<long>(left + 0.5)) + " s").c_str() : "?");
    if (done == total) std::fprintf(stderr, "\n");
    std::fflush(stderr);
  }

 private:
  bool enabled_;
  std::chrono::steady_clock::time_point start_;
};

// Every file name talus simulate may write into its output directory.
std::vector<std::string> TalusOutputNames() {
  std::vector<std::string> names = {
      "rocks.csv",    "trajectories.h5", "summary.json",         "quicklook.png",
      "passages.tif", "deposits.tif",    "reach_probability.tif"};
  for (const char* quantity : {"speed", "energy", "jump_height"})
    for (const char* statistic : {"max", "mean", "p95"})
      names.push_back(std::string(quantity) + "_" + statistic + ".tif");
  return names;
}

int RunSimulate(const SimulateArgs& args) {
  namespace fs = std::filesystem;
  io::SceneFile scene;
  try {
    scene = io::LoadScene(args.scene);
    if (args.rocks > 0) scene.release.rocks_per_release = args.rocks;
    if (args.seed) scene.release.seed = *args.seed;
    // The scene was valid; only --rocks can break it now (too many rocks in all).
    if (std::string why; !scene.release.IsValid(&why))
      throw InputError("--rocks " + std::to_string(args.rocks) + ": " + why);
  } catch (const InputError& e) {
    std::cerr << "talus simulate: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {  // e.g. out of memory while reading the inputs
    std::cerr << "talus simulate: cannot load " << args.scene << ": " << e.what() << "\n";
    return 1;
  }
  std::error_code error;
  fs::create_directories(args.out, error);
  if (error || !fs::is_directory(args.out)) {
    std::cerr << "talus simulate: cannot create the output directory " << args.out << "\n";
    return 2;
  }
  const auto out = [&](const std::string& name) { return (fs::path(args.out) / name).string(); };
  // An earlier run's outputs that this run would not replace must not pass for this run's.
  int stale = 0;
  for (const std::string& name : TalusOutputNames()) stale += fs::remove(out(name), error) ? 1 : 0;
  if (stale > 0)
    std::printf("Removed %d outputs of an earlier run from %s\n", stale, args.out.c_str());

  std::printf("Scene %s: %s; %s\n", args.scene.c_str(), scene.terrain_description.c_str(),
              DescribeRocks(scene).c_str());
  try {
    ensemble::EnsembleOptions options;
    options.threads = args.threads;
    options.trajectories = scene.output.trajectories;
    options.trajectory_interval_s = scene.output.trajectory_interval_s;
    options.sample_trajectories = scene.output.quicklook ? kQuickLookPaths : 0;
    const GridGeometry& dem = scene.scene.terrain.heights().grid;
    options.rasters = scene.output.Request(dem);
    ProgressBar progress;
    options.progress = [&progress](long done, long total) { progress(done, total); };

    std::vector<std::string> outputs = {"rocks.csv"};
    io::RocksCsvWriter csv(out("rocks.csv"), scene.release);
    std::unique_ptr<io::TrajectoryWriter> trajectories;
    if (scene.output.trajectories) {
      trajectories =
          std::make_unique<io::TrajectoryWriter>(out("trajectories.h5"), scene.scene.rock);
      outputs.push_back("trajectories.h5");
    }
    FileSink sink(csv, trajectories.get(), options.sample_trajectories);
    const ensemble::EnsembleReport report =
        ensemble::RunEnsemble(scene.scene, scene.release, options, &sink);
    csv.Commit();
    if (trajectories) trajectories->Commit();
    for (const ensemble::RasterLayer& layer : report.rasters) {
      io::WriteGeoTiff(out(layer.name + ".tif"), dem, scene.crs_wkt, layer.values, layer.has_nodata,
                       ensemble::RasterLayer::kNoData, layer.name + " (" + layer.unit + ")");
      outputs.push_back(layer.name + ".tif");
    }
    if (scene.output.quicklook) {
      io::WriteQuickLookPng(out("quicklook.png"), scene.scene.terrain.heights(),
                            io::QuickLookLayer(report.rasters), sink.paths);
      outputs.push_back("quicklook.png");
    }
    WriteFileAtomically(out("summary.json"), io::SummaryJson(scene, report, kVersion, outputs));
    std::printf("%s\n", report.BriefReport().c_str());
    std::printf("Wrote %zu files to %s\n", outputs.size() + 1, args.out.c_str());
    if (report.count(EndReason::kFailed) > 0)
      std::fprintf(stderr,
                   "talus simulate: %ld rocks failed numerically (end = failed in rocks.csv)\n",
                   report.count(EndReason::kFailed));
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "talus simulate: " << e.what() << "\n";
    return 1;
  }
}

}  // namespace

Runner AddSimulateCommand(CLI::App& app) {
  auto args = std::make_shared<SimulateArgs>();
  CLI::App* cmd = app.add_subcommand(
      "simulate", "Run a scene's rocks and write rocks.csv, rasters, trajectories");
  cmd->add_option("scene", args->scene, "Scene file (TOML)")->required();
  cmd->add_option("--out", args->out, "Output directory")->required();
  cmd->add_option("--rocks", args->rocks, "Rocks per release (overrides the scene)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--threads", args->threads, "Worker threads (default: all cores)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option_function<std::uint64_t>(
      "--seed", [args](const std::uint64_t& seed) { args->seed = seed; },
      "Random seed (overrides the scene)");
  return [cmd, args]() { return *cmd ? RunSimulate(*args) : -1; };
}

}  // namespace talus::app
