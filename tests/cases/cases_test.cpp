// The shipped cases stay loadable and runnable: every scene under cases/ loads without error, and a
// few of its rocks run to an ending other than failed, with the case's own rasters accumulated.

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "ensemble/runner.hpp"
#include "io/event_file.hpp"
#include "io/scene_file.hpp"

namespace talus {
namespace {

namespace fs = std::filesystem;

// Event files are event.toml and event_<what>.toml; every other .toml under cases/ is a scene.
bool IsEventFile(const fs::path& path) {
  const std::string stem = path.stem().string();
  return path.extension() == ".toml" && (stem == "event" || stem.rfind("event_", 0) == 0);
}

std::vector<fs::path> CaseScenes() {
  std::vector<fs::path> scenes;
  for (const auto& entry : fs::recursive_directory_iterator(fs::path(TALUS_SOURCE_DIR) / "cases"))
    if (entry.path().extension() == ".toml" && !IsEventFile(entry.path()))
      scenes.push_back(entry.path());
  std::sort(scenes.begin(), scenes.end());
  return scenes;
}

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

// Every case's event file (event.toml, event_<what>.toml) loads: its scene, its observation
// tables, its runs.
TEST(Cases, EveryEventLoads) {
  int events = 0;
  for (const auto& entry : fs::recursive_directory_iterator(fs::path(TALUS_SOURCE_DIR) / "cases"))
    if (IsEventFile(entry.path())) {
      SCOPED_TRACE(entry.path().string());
      const io::EventFile event = io::LoadEvent(entry.path().string());
      EXPECT_GT(event.observations.size(), 0u);
      ++events;
    }
  EXPECT_GE(events, 3);  // tschamut2014, chant_sura (impacts, segments)
}

}  // namespace
}  // namespace talus
