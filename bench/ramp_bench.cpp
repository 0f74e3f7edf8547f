// Benchmark: single-rock trajectories of the EOTA221 block down the 40 degree ramp, one core.
// Prints the machine, trajectories per second (median of repeats), steps per second, contact-solver
// sweeps per contact step and a per-stage time profile.

#include <sys/utsname.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <string>
#include <thread>
#include <vector>

#include "scenes/scenes.hpp"
#include "solver/simulate.hpp"

namespace {

std::string CpuModel() {
  std::ifstream in("/proc/cpuinfo");
  for (std::string line; std::getline(in, line);)
    if (line.rfind("model name", 0) == 0) return line.substr(line.find(':') + 2);
  return "unknown cpu";
}

struct Batch {
  double wall_s = 0;
  long steps = 0, contact_steps = 0, iterations = 0, unconverged = 0;
  double time_sum_s = 0;
  std::vector<double> runouts_m, max_speeds_m_s;
  std::map<std::string, int> endings;
};

Batch RunBatch(const talus::Scene& scene, int rocks, std::uint64_t seed, talus::StageTimes* times) {
  Batch batch;
  talus::SimulationWorkspace workspace;
  workspace.stage_times = times;
  const auto t0 = std::chrono::steady_clock::now();
  for (int k = 0; k < rocks; ++k) {
    const talus::RockState start = talus::scenes::Ramp40Release(scene, seed, k);
    const talus::RockResult r = talus::SimulateRock(scene, start, workspace);
    batch.steps += r.steps;
    batch.contact_steps += r.contact_steps;
    batch.iterations += r.solver_iterations;
    batch.unconverged += r.unconverged_steps;
    batch.runouts_m.push_back(r.runout_m);
    batch.max_speeds_m_s.push_back(r.max_speed_m_s);
    batch.time_sum_s += r.travel_time_s;
    ++batch.endings[talus::ToString(r.end)];
  }
  batch.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return batch;
}

double Quantile(std::vector<double> v, double q) {
  std::sort(v.begin(), v.end());
  const double position = q * (v.size() - 1);
  const std::size_t lo = static_cast<std::size_t>(position);
  const std::size_t hi = std::min(lo + 1, v.size() - 1);
  return v[lo] + (position - lo) * (v[hi] - v[lo]);
}
double Median(const std::vector<double>& v) { return Quantile(v, 0.5); }

// Mean and its standard error.
std::pair<double, double> MeanAndError(const std::vector<double>& v) {
  double mean = 0, var = 0;
  for (double x : v) mean += x / v.size();
  for (double x : v) var += (x - mean) * (x - mean) / (v.size() - 1);
  return {mean, std::sqrt(var / v.size())};
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Ramp benchmark: EOTA221 block trajectories down a 40 degree plane, one core"};
  int rocks = 200, repeats = 5;
  double dt_s = 0.002, tolerance = -1;
  int max_iterations = -1;
  std::uint64_t seed = 1;
  app.add_option("--rocks", rocks, "Trajectories per repeat")->check(CLI::PositiveNumber);
  app.add_option("--repeats", repeats, "Repeats (the median is reported)")
      ->check(CLI::PositiveNumber);
  app.add_option("--dt", dt_s, "Time step, s")->check(CLI::PositiveNumber);
  app.add_option("--tolerance", tolerance,
                 "Contact solver tolerance, m/s (default: solver default)");
  app.add_option("--max-iterations", max_iterations,
                 "Contact solver sweeps at most (default: solver default)");
  app.add_option("--seed", seed, "Seed of the release orientations");
  CLI11_PARSE(app, argc, argv);

  talus::Scene scene = talus::scenes::Ramp40();
  scene.options.dt_s = dt_s;
  if (tolerance > 0) scene.options.tolerance_m_s = tolerance;
  if (max_iterations > 0) scene.options.max_iterations = max_iterations;
  std::string why;
  if (!scene.IsValid(&why)) {
    std::fprintf(stderr, "ramp_bench: %s\n", why.c_str());
    return 1;
  }

  utsname host{};
  uname(&host);
  std::printf("machine: %s, %u hardware threads, %s %s\n", CpuModel().c_str(),
              std::thread::hardware_concurrency(), host.sysname, host.release);
  std::printf("compiler: %s, build: %s\n", __VERSION__,
#ifdef NDEBUG
              "optimised (NDEBUG)"
#else
              "debug"
#endif
  );
  std::printf(
      "scene: EOTA221 %.0f kg, %zu hull vertices; 40 deg ramp 200 m + 150 m runout, 2 m cells, "
      "medium_hard; dt %.4f s, tolerance %.1e m/s, at most %d sweeps\n",
      scene.rock.mass_kg, scene.rock.vertices_m.size(), scene.options.dt_s,
      scene.options.tolerance_m_s, scene.options.max_iterations);

  std::vector<double> rates, step_rates;
  Batch last;
  for (int r = 0; r < repeats; ++r) {
    last = RunBatch(scene, rocks, seed, nullptr);
    rates.push_back(rocks / last.wall_s);
    step_rates.push_back(last.steps / last.wall_s);
    std::printf("repeat %d: %d trajectories in %.3f s = %.1f trajectories/s\n", r + 1, rocks,
                last.wall_s, rates.back());
  }
  std::printf("\ntrajectories per second (one core, median of %d): %.1f\n", repeats, Median(rates));
  std::printf("steps per second (median): %.3g\n", Median(step_rates));
  const auto [runout, runout_error] = MeanAndError(last.runouts_m);
  const auto [speed, speed_error] = MeanAndError(last.max_speeds_m_s);
  std::printf("mean simulated time per trajectory: %.2f s\n", last.time_sum_s / rocks);
  std::printf(
      "accuracy figures (compare across --dt / --tolerance): runout mean %.1f +- %.1f m, "
      "median %.1f m, 95th percentile %.1f m; max speed mean %.2f +- %.2f m/s\n",
      runout, runout_error, Median(last.runouts_m), Quantile(last.runouts_m, 0.95), speed,
      speed_error);
  std::printf(
      "contact steps: %.1f %% of steps; mean Gauss-Seidel sweeps per contact step: %.2f; "
      "unconverged steps: %ld\n",
      100.0 * last.contact_steps / last.steps,
      last.contact_steps ? double(last.iterations) / last.contact_steps : 0.0, last.unconverged);
  std::printf("endings:");
  for (const auto& [end, count] : last.endings) std::printf(" %s %d", end.c_str(), count);
  std::printf(
      "\nreference: RAMMS::ROCKFALL 1000 trajectories in 161.5 s = 6.2 trajectories/s "
      "(Leine et al. 2021, Table 1)\n");

  // Stage profile in a separate run (the clock calls cost time of their own).
  talus::StageTimes times;
  const Batch profiled = RunBatch(scene, std::max(1, rocks / 4), seed, &times);
  const double total =
      times.midpoint_s + times.free_rotation_s + times.contacts_s + times.solve_s + times.end_s;
  std::printf("\nstage profile (%ld steps, %.0f ns/step timed):\n", times.steps,
              1e9 * total / times.steps);
  const std::pair<const char*, double> stages[] = {{"midpoint", times.midpoint_s},
                                                   {"free rotation", times.free_rotation_s},
                                                   {"contact detection", times.contacts_s},
                                                   {"contact solve", times.solve_s},
                                                   {"end point + scar", times.end_s}};
  for (const auto& [name, seconds] : stages)
    std::printf("  %-18s %6.1f %%  %6.0f ns/step\n", name, 100 * seconds / total,
                1e9 * seconds / times.steps);
  (void)profiled;
  return 0;
}
