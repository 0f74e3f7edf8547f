// talus simulate: run a scene's ensemble and write rocks.csv, rasters, trajectories and a summary.

#include <cpl_error.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <limits>
#include <memory>
#include <optional>
#include <string>

#include "app/commands.hpp"
#include "app/interrupt.hpp"
#include "common/atomic_file.hpp"
#include "common/error.hpp"
#include "ensemble/runner.hpp"
#include "io/quicklook.hpp"
#include "io/raster.hpp"
#include "io/resources.hpp"
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
    ThrowIfInterrupted();
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

// Keeps GDAL's error messages off stderr while alive (on this thread); they stay readable through
// CPLGetLastErrorMsg, which the raster writers put in their exceptions.
class QuietGdal {
 public:
  QuietGdal() { CPLPushErrorHandler(CPLQuietErrorHandler); }
  ~QuietGdal() { CPLPopErrorHandler(); }
  QuietGdal(const QuietGdal&) = delete;
  QuietGdal& operator=(const QuietGdal&) = delete;
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
    shown_ = done < total;
    if (done == total) std::fprintf(stderr, "\n");
    std::fflush(stderr);
  }
  // Ends a bar left unfinished, so that a message starts on a line of its own.
  void Break() {
    if (shown_) std::fprintf(stderr, "\n");
    shown_ = false;
  }

 private:
  bool enabled_;
  bool shown_ = false;
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
  if (std::error_code error; fs::is_directory(args.scene, error)) {
    std::cerr << "talus simulate: " << args.scene << " is a directory, not a scene file";
    if (fs::is_regular_file(fs::path(args.scene) / "scene.toml", error))
      std::cerr << " (did you mean " << (fs::path(args.scene) / "scene.toml").string() << "?)";
    std::cerr << "\n";
    return kExitBadInput;
  }
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
    return kExitBadInput;
  } catch (const std::exception& e) {  // e.g. out of memory while reading the inputs
    std::cerr << "talus simulate: cannot load " << args.scene << ": " << e.what() << "\n";
    return kExitRunFailed;
  }
  if (const std::string why = PrepareOutputDirectory(args.out); !why.empty()) {
    std::cerr << "talus simulate: " << why << "\n";
    return kExitBadInput;
  }
  // A run too large for this machine fails now, with the estimate and the knob to turn.
  const io::ResourceEstimate needs = io::EstimateResources(
      scene, ensemble::WorkerThreads(args.threads, scene.release.total_rocks()));
  const io::MachineCapacity capacity = io::MeasureCapacity(args.out);
  if (const std::string why = io::CheckResources(needs, capacity); !why.empty()) {
    std::cerr << "talus simulate: " << why << "\n";
    return kExitBadInput;
  }
  // From here on SIGINT / SIGTERM unwind the run: no temporary file is left behind.
  const InterruptScope interrupts;
  std::signal(SIGXFSZ, SIG_IGN);  // a file-size limit is a write error ("File too large")
  if (const auto stale = RemoveStaleTemporaries(args.out); !stale.empty())
    std::printf("Removed %zu temporary files of interrupted runs from %s\n", stale.size(),
                args.out.c_str());

  std::printf("Scene %s: %s; %s\n", args.scene.c_str(), scene.terrain_description.c_str(),
              DescribeRocks(scene).c_str());
  std::printf(
      "Needs about %s of memory (%s available) and %s of disk (%s free)\n",
      io::FormatBytes(needs.memory_bytes()).c_str(), io::FormatBytes(capacity.memory_bytes).c_str(),
      io::FormatBytes(needs.disk_bytes()).c_str(), io::FormatBytes(capacity.disk_bytes).c_str());
  std::fflush(stdout);
  // Every output is written into a staging directory and moved into --out only when all are
  // complete: a failed or interrupted run leaves --out as it was.
  std::optional<StagingDirectory> staging;
  ProgressBar progress;
  try {
    staging.emplace(args.out);
    const auto out = [&](const std::string& name) { return staging->path(name); };
    ensemble::EnsembleOptions options;
    options.threads = args.threads;
    options.trajectories = scene.output.trajectories;
    options.trajectory_interval_s = scene.output.trajectory_interval_s;
    options.sample_trajectories = scene.output.quicklook ? kQuickLookPaths : 0;
    const GridGeometry& dem = scene.scene.terrain.heights().grid;
    options.rasters = scene.output.Request(dem);
    // Thrown on the calling thread, Interrupted stops the workers and comes out of RunEnsemble.
    options.progress = [&progress](long done, long total) {
      ThrowIfInterrupted();
      progress(done, total);
    };

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
    ThrowIfInterrupted();
    csv.Commit();
    if (trajectories) trajectories->Commit();
    // GDAL would print every failed write of a full disk; the writers throw with its last message.
    const QuietGdal quiet_gdal;
    for (const ensemble::RasterLayer& layer : report.rasters) {
      ThrowIfInterrupted();
      io::WriteGeoTiff(out(layer.name + ".tif"), dem, scene.crs_wkt, layer.values, layer.has_nodata,
                       ensemble::RasterLayer::kNoData, layer.name + " (" + layer.unit + ")");
      outputs.push_back(layer.name + ".tif");
    }
    ThrowIfInterrupted();
    if (scene.output.quicklook) {
      io::WriteQuickLookPng(out("quicklook.png"), scene.scene.terrain.heights(),
                            io::QuickLookLayer(report.rasters), sink.paths);
      outputs.push_back("quicklook.png");
    }
    WriteFileAtomically(out("summary.json"), io::SummaryJson(scene, report, kVersion, outputs));
    ThrowIfInterrupted();
    std::vector<std::string> commit = outputs;
    commit.push_back("summary.json");  // last: a summary.json is there only with its outputs
    staging->Commit(commit);
    // An earlier run's outputs that this run did not replace must not pass for this run's.
    int stale = 0;
    for (const std::string& name : TalusOutputNames()) {
      if (std::find(commit.begin(), commit.end(), name) != commit.end()) continue;
      std::error_code error;
      stale += fs::remove(fs::path(args.out) / name, error) ? 1 : 0;
    }
    if (stale > 0)
      std::printf("Removed %d outputs of an earlier run from %s\n", stale, args.out.c_str());
    std::printf("%s\n", report.BriefReport().c_str());
    std::printf("Wrote %zu files to %s\n", commit.size(), args.out.c_str());
    if (report.count(EndReason::kFailed) > 0)
      std::fprintf(stderr,
                   "talus simulate: %ld rocks failed numerically (end = failed in rocks.csv)\n",
                   report.count(EndReason::kFailed));
    return kExitOk;
  } catch (const Interrupted& e) {
    staging.reset();
    progress.Break();
    std::cerr << "talus simulate: " << e.what() << "; removed this run's temporary files, "
              << args.out << " is as it was before the run\n";
    return ExitCodeForSignal(e.signal());
  } catch (const std::exception& e) {
    const std::string message = staging ? staging->Describe(e.what()) : e.what();
    staging.reset();
    progress.Break();
    std::cerr << "talus simulate: " << message << " (no output written)\n";
    return kExitRunFailed;
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
      ->check(IntegerRange(1, std::numeric_limits<long>::max()));
  cmd->add_option("--threads", args->threads, "Worker threads (default: all cores)")
      ->check(ThreadCount());
  // The scene's range: a seed given here can be written in the scene file and the other way round.
  cmd->add_option_function<std::uint64_t>(
         "--seed", [args](const std::uint64_t& seed) { args->seed = seed; },
         "Random seed (overrides the scene)")
      ->check(IntegerRange(0, std::numeric_limits<std::int64_t>::max()));
  return [cmd, args]() { return *cmd ? RunSimulate(*args) : -1; };
}

}  // namespace talus::app
