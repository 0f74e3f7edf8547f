// The shipped cases stay loadable and runnable: every scene under cases/ loads without error, and a
// few of its rocks run to an ending other than failed, with the case's own rasters accumulated.

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "ensemble/runner.hpp"
#include "io/calibration_file.hpp"
#include "io/event_file.hpp"
#include "io/scene_file.hpp"

namespace talus {
namespace {

namespace fs = std::filesystem;

// The cases' TOML files of one kind, told apart by their first key: an event names its `scene`,
// a calibration file its `event`; every other TOML file is a scene.
enum class Kind { kScene, kEvent, kCalibration };
Kind KindOf(const fs::path& path) {
  std::ifstream in(path);
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("scene =", 0) == 0) return Kind::kEvent;
    if (line.rfind("event =", 0) == 0) return Kind::kCalibration;
  }
  return Kind::kScene;
}

std::vector<fs::path> CaseFiles(Kind kind) {
  std::vector<fs::path> files;
  for (const auto& entry : fs::recursive_directory_iterator(fs::path(TALUS_SOURCE_DIR) / "cases"))
    if (entry.path().extension() == ".toml" && KindOf(entry.path()) == kind)
      files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  return files;
}

std::vector<fs::path> CaseScenes() { return CaseFiles(Kind::kScene); }

TEST(Cases, EverySceneLoadsAndItsFirstRocksRun) {
  const std::vector<fs::path> scenes = CaseScenes();
  ASSERT_GE(scenes.size(), 5u);  // ramp40, slope30 (3 grounds), tirol
  for (const fs::path& path : scenes) {
    SCOPED_TRACE(path.string());
    io::SceneFile scene = io::LoadScene(path.string());
    scene.release.rocks_per_release = 2;
    scene.scene.options.max_time_s = 20;
    ensemble::EnsembleOptions options;
    options.threads = 2;
    options.rasters = scene.output.Request(scene.scene.terrain.heights().grid);
    const ensemble::EnsembleReport report =
        ensemble::RunEnsemble(scene.scene, scene.release, options);
    EXPECT_EQ(report.rocks, scene.release.total_rocks());
    EXPECT_EQ(report.count(EndReason::kFailed), 0);
    EXPECT_EQ(report.rasters.empty(), scene.output.rasters.empty());
  }
}

// Every case's event file loads: its scene, its observation tables, its runs.
TEST(Cases, EveryEventLoads) {
  int events = 0;
  for (const fs::path& path : CaseFiles(Kind::kEvent)) {
    SCOPED_TRACE(path.string());
    const io::EventFile event = io::LoadEvent(path.string());
    EXPECT_GT(event.observations.size(), 0u);
    ++events;
  }
  EXPECT_GE(events, 4);  // tschamut2014 (2), chant_sura (impacts, segments)
}

// Every case's calibration file loads and is checked (event, parameters, optimiser).
TEST(Cases, EveryCalibrationFileLoads) {
  int files = 0;
  for (const fs::path& path : CaseFiles(Kind::kCalibration)) {
    SCOPED_TRACE(path.string());
    const io::CalibrationFile file = io::LoadCalibration(path.string());
    EXPECT_FALSE(file.parameters.empty());
    ++files;
  }
  EXPECT_GE(files, 1);  // tschamut2014
}

// The Chant Sura single impacts (cases/chant_sura/scene_impacts.toml): every rock's first contact
// episode, the simulated impact, starts at release and is ended by a flight before max_time_s, so
// the run is long enough for what is scored.
TEST(Cases, ChantSuraSingleImpactsEndTheirFirstEpisodeInFlight) {
  io::SceneFile scene =
      io::LoadScene((fs::path(TALUS_SOURCE_DIR) / "cases/chant_sura/scene_impacts.toml").string());
  ensemble::EnsembleOptions options;
  options.threads = 2;
  options.episodes = true;
  struct Episodes : ensemble::RockSink {
    double max_time_s = 0;
    long rocks = 0;
    void OnRock(const ensemble::RockOutcome& rock) override {
      ++rocks;
      ASSERT_FALSE(rock.episodes.empty()) << rock.rock;
      const ContactEpisode& first = rock.episodes.front();
      EXPECT_LE(first.start_time_s, 0.002 + 1e-12) << rock.rock;  // at once
      // Ended by a flight of EpisodeOptions::min_flight_s, not by the end of the run.
      EXPECT_LT(first.end_time_s, max_time_s - 0.05) << rock.rock;
    }
  } sink;
  sink.max_time_s = scene.scene.options.max_time_s;
  ensemble::RunEnsemble(scene.scene, scene.release, options, &sink);
  EXPECT_EQ(sink.rocks, 6 * scene.release.rocks_per_release);
}

}  // namespace
}  // namespace talus
