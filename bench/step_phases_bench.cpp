// Benchmark: where a step's error comes from, phase by phase. The scene's rocks run at a fine step;
// every `interval` seconds of each rock's path its state is kept. From each kept state the rock
// then runs a window of `window` seconds twice, at the fine and at the coarse step, each from a
// fresh workspace. The same start, so the comparison is between like phases, before the paths
// part: per class of the start (the centre of mass's speed, and whether the step that ended there
// carried load) the mechanical energy each run lost per kilogram, the difference coarse - fine with
// its standard error, the share of the window's steps that carried load and the mean scar length.
// A class where the coarse step loses less energy than the fine one is where its rocks run further.

#include <CLI/CLI.hpp>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "bench/bench_main.hpp"
#include "ensemble/runner.hpp"
#include "io/scene_file.hpp"
#include "solver/simulate.hpp"
#include "solver/step.hpp"

namespace {

struct Start {
  std::shared_ptr<const talus::RockShape> shape;
  talus::RockState state;
  bool loaded = false;  // the step that ended in this state carried load
};

// Keeps a rock's state every `interval_s` of its path (RunEnsemble, one thread).
class StartRecorder : public talus::ensemble::RockRecorder {
 public:
  StartRecorder(double interval_s, std::vector<Start>* out) : interval_s_(interval_s), out_(out) {}
  void Begin(const talus::ensemble::RockOutcome& outcome) override {
    shape_ = outcome.shape;
    next_s_ = interval_s_;
  }
  void OnStep(const talus::RockState& state, const talus::StepReport& step,
              const talus::TerrainSample&) override {
    if (state.time_s < next_s_) return;
    next_s_ += interval_s_;
    out_->push_back({shape_, state, step.loaded});
  }
  void Finish(talus::ensemble::RockOutcome&) override {}

 private:
  double interval_s_, next_s_ = 0;
  std::vector<Start>* out_;
  std::shared_ptr<const talus::RockShape> shape_;
};

double MechanicalEnergy(const talus::Scene& scene, const talus::RockShape& rock,
                        const talus::RockState& s) {
  return talus::KineticEnergy(rock, s) +
         rock.mass_kg * scene.options.gravity_m_s2 * s.position_m.z();
}

// One window from a start: energy change per kg, share of loaded steps, mean scar. False when the
// rock left the DEM or the state stopped being finite.
struct Window {
  double energy_j_kg = 0, loaded = 0, scar_m = 0;
};

bool RunWindow(const talus::Scene& scene, const Start& start, double window_s, Window* out) {
  talus::StepWorkspace workspace;
  workspace.Reset(start.shape->vertices_m.size());
  talus::RockState s = start.state;
  const long steps = std::lround(window_s / scene.options.dt_s);
  double loaded = 0, scar = 0;
  for (long k = 0; k < steps; ++k) {
    const talus::StepReport r = talus::Step(scene, *start.shape, s, workspace);
    if (r.outside_domain || !s.position_m.allFinite()) return false;
    loaded += r.loaded;
    scar += s.scar_m;
  }
  *out = {(MechanicalEnergy(scene, *start.shape, s) -
           MechanicalEnergy(scene, *start.shape, start.state)) /
              start.shape->mass_kg,
          loaded / steps, scar / steps};
  return true;
}

struct Tally {
  long n = 0;
  double fine = 0, coarse = 0, diff = 0, diff2 = 0;
  double loaded_fine = 0, loaded_coarse = 0, scar_fine = 0, scar_coarse = 0;
  void Add(const Window& f, const Window& c) {
    ++n;
    fine += f.energy_j_kg;
    coarse += c.energy_j_kg;
    const double d = c.energy_j_kg - f.energy_j_kg;
    diff += d;
    diff2 += d * d;
    loaded_fine += f.loaded;
    loaded_coarse += c.loaded;
    scar_fine += f.scar_m;
    scar_coarse += c.scar_m;
  }
};

}  // namespace

int RunBenchmark(int argc, char** argv) {
  CLI::App app{"Step error by phase: windows from the same states at a fine and a coarse step"};
  std::string scene_path;
  app.add_option("scene", scene_path, "Scene file (TOML)")->required();
  long rocks = 4;
  app.add_option("--rocks", rocks, "Rocks per release (run) for the fine run")
      ->check(CLI::PositiveNumber);
  unsigned long seed = 1;
  app.add_option("--seed", seed, "Release seed");
  double fine_s = 0.00025, coarse_s = 0.002, window_s = 0.1, interval_s = 0.25;
  app.add_option("--fine-dt", fine_s, "Fine step, s")->check(CLI::PositiveNumber);
  app.add_option("--coarse-dt", coarse_s, "Coarse step, s")->check(CLI::PositiveNumber);
  app.add_option("--window", window_s, "Window run from each start, s")->check(CLI::PositiveNumber);
  app.add_option("--interval", interval_s, "Time between starts along a rock's path, s")
      ->check(CLI::PositiveNumber);
  CLI11_PARSE(app, argc, argv);
  PrintMachine(argc, argv);

  talus::io::SceneFile file = talus::io::LoadScene(scene_path);
  talus::Scene fine = file.scene, coarse = file.scene;
  fine.options.dt_s = fine_s;
  coarse.options.dt_s = coarse_s;
  talus::ensemble::ReleaseSpec release = file.release;
  release.seed = seed;
  release.SetRocksPerRelease(rocks);
  std::vector<Start> starts;
  talus::ensemble::EnsembleOptions options;
  options.threads = 1;
  options.extra_recorders.push_back(
      [&] { return std::make_unique<StartRecorder>(interval_s, &starts); });
  talus::ensemble::RunEnsemble(fine, release, options, nullptr);

  // Classes: speed of the centre of mass at the start (upper bounds, m/s), and whether the step
  // that ended there carried load; each start also counts in its speed's "all".
  constexpr std::array<double, 5> kSpeeds = {0.5, 2, 5, 10, INFINITY};
  std::map<std::pair<int, int>, Tally> tallies;
  long left = 0;
  for (const Start& start : starts) {
    Window f, c;
    if (!RunWindow(fine, start, window_s, &f) || !RunWindow(coarse, start, window_s, &c)) {
      ++left;
      continue;
    }
    int bin = 0;
    while (start.state.velocity_m_s.norm() > kSpeeds[bin]) ++bin;
    tallies[{bin, start.loaded ? 1 : 0}].Add(f, c);
    tallies[{bin, 2}].Add(f, c);
  }
  std::printf("%zu starts (%ld left the DEM within a window); windows of %g s at %g and %g s\n\n",
              starts.size(), left, window_s, fine_s, coarse_s);
  std::printf(
      "| speed (m/s) | start | windows | energy change, fine (J/kg) | coarse (J/kg) | "
      "coarse - fine (J/kg) | loaded steps, fine | coarse | mean scar, fine (m) | coarse (m) |\n"
      "|---|---|---|---|---|---|---|---|---|---|\n");
  for (const auto& [key, t] : tallies) {
    const double mean = t.diff / t.n;
    const double se =
        t.n > 1 ? std::sqrt(std::max(0.0, t.diff2 / t.n - mean * mean) / (t.n - 1)) : NAN;
    const double low = key.first == 0 ? 0 : kSpeeds[key.first - 1];
    std::printf("| %g-%g | %s | %ld | %.4f | %.4f | %+.4f ± %.4f%s | %.3f | %.3f | %.4f | %.4f |\n",
                low, kSpeeds[key.first],
                key.second == 2 ? "all"
                : key.second    ? "loaded"
                                : "not loaded",
                t.n, t.fine / t.n, t.coarse / t.n, mean, se,
                std::abs(mean) > 2 * se ? " **≠**" : "", t.loaded_fine / t.n, t.loaded_coarse / t.n,
                t.scar_fine / t.n, t.scar_coarse / t.n);
  }
  return 0;
}
