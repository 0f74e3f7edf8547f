// Benchmark: what the steps of a scene's rocks are, one core, no outputs. Prints the share of steps
// with a contact, of contact-free steps, of steps that needed no vertex test (bounding sphere clear
// of the terrain, or in a flight window) and of steps taken in flight windows (solver/flight.hpp),
// and the wall time with and without flight windows (the same rocks, bit for bit), alternated.

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include "io/scene_file.hpp"
#include "solver/simulate.hpp"

namespace {

class StepKinds : public talus::StepObserver {
 public:
  void OnStep(const talus::RockState&, const talus::StepReport& step,
              const talus::TerrainSample&) override {
    ++steps;
    contact += step.contacts > 0;
    clear += step.clear;
  }
  long steps = 0, contact = 0, clear = 0;
};

struct Run {
  StepKinds kinds;
  long flight_steps = 0;
  double wall_s = 0;
};

Run RunRocks(const talus::io::SceneFile& file, long rocks, bool flight_windows) {
  Run run;
  talus::SimulationWorkspace workspace;
  workspace.flight_windows = flight_windows;
  const auto t0 = std::chrono::steady_clock::now();
  for (long k = 0; k < rocks; ++k) {
    const talus::ensemble::ReleasedRock rock =
        talus::ensemble::Release(file.scene, file.release, k);
    run.flight_steps +=
        talus::SimulateRock(file.scene, *rock.shape, rock.start, workspace, &run.kinds)
            .flight_steps;
  }
  run.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return run;
}

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Step kinds: contact, flight, flight windows, over a scene's rocks on one core"};
  std::string scene_path;
  long rocks = 0;
  app.add_option("scene", scene_path, "Scene file (TOML)")->required();
  app.add_option("--rocks", rocks, "Rocks to run (default: the scene's)");
  int repeats = 3;
  app.add_option("--repeats", repeats, "Runs of each way (the median is reported)")
      ->check(CLI::PositiveNumber);
  CLI11_PARSE(app, argc, argv);
  const talus::io::SceneFile file = talus::io::LoadScene(scene_path);
  if (rocks <= 0 || rocks > file.release.total_rocks()) rocks = file.release.total_rocks();

  // Both ways, alternating which goes first; medians of the wall times.
  std::vector<double> every_s, windows_s;
  Run every, windows;
  for (int r = 0; r < repeats; ++r) {
    for (bool flight_windows : {r % 2 == 1, r % 2 == 0}) {
      Run run = RunRocks(file, rocks, flight_windows);
      (flight_windows ? windows_s : every_s).push_back(run.wall_s);
      (flight_windows ? windows : every) = run;
    }
  }
  const StepKinds& k = windows.kinds;
  const double steps = static_cast<double>(k.steps);
  std::printf("%s, %ld rocks, %ld steps: %.1f %% with a contact, %.1f %% without\n",
              scene_path.c_str(), rocks, k.steps, 100 * k.contact / steps,
              100 * (k.steps - k.contact) / steps);
  std::printf("no vertex test: %.1f %% with flight windows, %.1f %% with detection in every step\n",
              100 * k.clear / steps, 100 * every.kinds.clear / steps);
  std::printf("flight windows: %.1f %% of the steps\n", 100 * windows.flight_steps / steps);
  std::printf(
      "wall time, one core (median of %d): %.2f s with flight windows, %.2f s with detection in "
      "every step\n",
      repeats, Median(windows_s), Median(every_s));
  return 0;
}
