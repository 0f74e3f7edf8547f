// Benchmark: single-rock trajectories of the EOTA221 block down the 40 degree ramp, one core.
// Prints the machine, trajectories per second (median of repeats), steps per second, contact-solver
// sweeps per contact step, the ramp statistics that Leine et al. 2021 (Table 2) report for
// RAMMS::ROCKFALL, per rock and pooled per raster cell (RAMMS's statistic mode), and a per-stage
// time profile.

#include <sys/utsname.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <fstream>
#include <map>
#include <memory>
#include <numbers>
#include <string>
#include <thread>
#include <vector>

#include "bench/bench_main.hpp"
#include "ensemble/rasters.hpp"
#include "scenes/scenes.hpp"
#include "solver/simulate.hpp"

namespace {

// The names of an enum's values, for CLI11's IsMember.
std::vector<std::string> Names(const talus::EnumNames& names) {
  return {names.names.begin(), names.names.end()};
}

std::string CpuModel() {
  std::ifstream in("/proc/cpuinfo");
  for (std::string line; std::getline(in, line);)
    if (line.rfind("model name", 0) == 0) return line.substr(line.find(':') + 2);
  return "unknown cpu";
}

struct Batch {
  double wall_s = 0;
  long steps = 0, contact_steps = 0, iterations = 0, unconverged = 0, flight_steps = 0;
  double time_sum_s = 0;
  std::vector<double> runouts_m, max_speeds_m_s, rotation_rates_1_s, jump_heights_m, travel_times_s,
      kinetic_energies_kj;
  int stopped_within_5_m = 0;
  std::map<std::string, int> endings;
};

Batch RunBatch(const talus::Scene& scene, int rocks, std::uint64_t seed, bool flight_windows,
               talus::StageTimes* times) {
  Batch batch;
  talus::SimulationWorkspace workspace;
  workspace.stage_times = times;
  workspace.flight_windows = flight_windows;
  const auto t0 = std::chrono::steady_clock::now();
  for (int k = 0; k < rocks; ++k) {
    const talus::RockState start = talus::scenes::Ramp40Release(scene, seed, k);
    const talus::RockResult r = talus::SimulateRock(scene, start, workspace);
    batch.steps += r.steps;
    batch.contact_steps += r.contact_steps;
    batch.iterations += r.solver_iterations;
    batch.unconverged += r.unconverged_steps;
    batch.flight_steps += r.flight_steps;
    batch.runouts_m.push_back(r.runout_m);
    batch.max_speeds_m_s.push_back(r.max_speed_m_s);
    batch.rotation_rates_1_s.push_back(r.max_angular_speed_rad_s / (2 * std::numbers::pi));
    batch.jump_heights_m.push_back(r.max_jump_height_m);
    batch.travel_times_s.push_back(r.travel_time_s);
    batch.kinetic_energies_kj.push_back(r.max_kinetic_energy_j / 1000);
    batch.stopped_within_5_m += r.end == talus::EndReason::kRest && r.runout_m < 5;
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

// Mean and standard deviation.
std::pair<double, double> MeanAndSd(const std::vector<double>& v) {
  double mean = 0, var = 0;
  for (double x : v) mean += x / v.size();
  for (double x : v) var += (x - mean) * (x - mean) / (v.size() - 1);
  return {mean, std::sqrt(var)};
}

// Mean and its standard error.
std::pair<double, double> MeanAndError(const std::vector<double>& v) {
  double mean = 0, var = 0;
  for (double x : v) mean += x / v.size();
  for (double x : v) var += (x - mean) * (x - mean) / (v.size() - 1);
  return {mean, std::sqrt(var / v.size())};
}

// RAMMS's statistic mode, pooled: for each rock and each raster cell its centre of mass passed,
// that rock's maximum of a quantity in that cell; the values of all rocks and cells together.
struct CellValues {
  std::vector<double> speeds_m_s, rotation_rates_1_s, jump_heights_m, kinetic_energies_kj;
};

// Records each rock's per-cell maxima with the recorder of `talus simulate`'s rasters
// (ensemble::FootprintRecorder: same cells, same marking of the cells a long step crosses). Its
// footprint has no angular speed, so a second recorder sees each state with the angular velocity
// in place of the velocity: the "speed" it records per cell is the angular speed.
class CellMaxima : public talus::StepObserver {
 public:
  CellMaxima(const talus::Scene& scene, CellValues* out)
      : motion_request_(Request(scene, true)),
        spin_request_(Request(scene, false)),
        motion_(motion_request_, scene.terrain),
        spin_(spin_request_, scene.terrain),
        shape_(std::make_shared<const talus::RockShape>(scene.rock)),
        out_(out) {}

  void Begin(const talus::RockState& start) {
    talus::ensemble::RockOutcome outcome;
    outcome.shape = shape_;
    outcome.start = start;
    motion_.Begin(outcome);
    outcome.start = WithSpinAsVelocity(start);
    spin_.Begin(outcome);
  }
  void OnStep(const talus::RockState& state, const talus::StepReport& step,
              const talus::TerrainSample& ground) override {
    motion_.OnStep(state, step, ground);
    spin_.OnStep(WithSpinAsVelocity(state), step, ground);
  }
  void Finish(const talus::RockResult& result) {
    talus::ensemble::RockOutcome motion, spin;
    motion.result = spin.result = result;
    motion_.Finish(motion);
    spin_.Finish(spin);
    const talus::ensemble::Footprint& m = motion.footprint;
    for (std::size_t k = 0; k < m.cells.size(); ++k) {
      out_->speeds_m_s.push_back(m.speed_m_s[k]);
      out_->jump_heights_m.push_back(m.jump_height_m[k]);
      out_->kinetic_energies_kj.push_back(m.energy_j[k] / 1000);
    }
    for (float w : spin.footprint.speed_m_s)
      out_->rotation_rates_1_s.push_back(w / (2 * std::numbers::pi));
  }

 private:
  static talus::ensemble::RasterRequest Request(const talus::Scene& scene, bool motion) {
    talus::ensemble::RasterRequest request;
    request.grid = scene.terrain.heights().grid;
    request.speed = true;
    request.energy = request.jump_height = motion;
    return request;
  }
  static talus::RockState WithSpinAsVelocity(talus::RockState state) {
    state.velocity_m_s = state.angular_velocity_rad_s;
    return state;
  }

  talus::ensemble::RasterRequest motion_request_, spin_request_;
  talus::ensemble::FootprintRecorder motion_, spin_;
  std::shared_ptr<const talus::RockShape> shape_;
  CellValues* out_;
};

CellValues RunCellStatistics(const talus::Scene& scene, int rocks, std::uint64_t seed) {
  CellValues values;
  CellMaxima recorder(scene, &values);
  talus::SimulationWorkspace workspace;
  for (int k = 0; k < rocks; ++k) {
    const talus::RockState start = talus::scenes::Ramp40Release(scene, seed, k);
    recorder.Begin(start);
    recorder.Finish(talus::SimulateRock(scene, start, workspace, &recorder));
  }
  return values;
}

// The command line.
struct BenchArgs {
  int rocks = 200, repeats = 5;
  double dt_s = 0.002, tolerance = -1;
  int max_iterations = -1;
  std::uint64_t seed = 1;
  std::string viscous = talus::ToString(talus::SolverOptions{}.viscous);
  std::string contact_solve = talus::ToString(talus::SolverOptions{}.contact_solve);
  bool no_profile = false, no_cells = false;
  // The scarring soil (Lu et al. 2019) under the ramp's medium_hard ground: its model, M_E and C_s
  // (the paper's whole-trajectory soil by default), and where its drag acts.
  std::string ground_model = "hard", soil_drag = "centre_of_mass";
  double soil_strength = 15, compaction_drag = 1.5;
  bool detect_every_step = false;
};

// The options of `app`, read into *args.
void AddOptions(CLI::App& app, BenchArgs* args) {
  app.add_option("--rocks", args->rocks, "Trajectories per repeat")->check(CLI::PositiveNumber);
  app.add_option("--repeats", args->repeats, "Repeats (the median is reported)")
      ->check(CLI::PositiveNumber);
  app.add_option("--dt", args->dt_s, "Time step, s")->check(CLI::PositiveNumber);
  app.add_option("--tolerance", args->tolerance,
                 "Contact solver tolerance, m/s (default: solver default)");
  app.add_option("--max-iterations", args->max_iterations,
                 "Contact solver sweeps at most (default: solver default)");
  app.add_option("--seed", args->seed, "Seed of the release orientations");
  app.add_option("--viscous,--drag", args->viscous,
                 "Reading of the viscous ground term: centre_of_mass or contact_friction")
      ->check(CLI::IsMember(Names(talus::kViscousReadingNames)));
  app.add_option("--contact-solve", args->contact_solve,
                 "Two-contact steps: gauss_seidel sweeps or one block solve")
      ->check(CLI::IsMember(Names(talus::kContactSolveMethodNames)));
  app.add_flag("--no-profile", args->no_profile,
               "Skip the stage profile and the per-cell statistics runs (for instruction counts "
               "of exactly --rocks trajectories)");
  app.add_flag("--no-cells", args->no_cells, "Skip the per-cell statistics run");
  app.add_option("--ground-model", args->ground_model,
                 "hard (the seed's) or lu2019 (scarring soil)")
      ->check(CLI::IsMember(Names(talus::kGroundModelNames)));
  app.add_option("--soil-strength", args->soil_strength, "lu2019: M_E, MN/m^2");
  app.add_option("--compaction-drag", args->compaction_drag, "lu2019: C_s");
  app.add_option("--soil-drag", args->soil_drag, "lu2019: where the drag acts")
      ->check(CLI::IsMember(Names(talus::kSoilDragPointNames)));
  app.add_flag("--detect-every-step", args->detect_every_step,
               "Contact detection in every step, no flight windows (same results, bit for bit)");
}

// The ramp with the options and the ground model asked for.
talus::Scene MakeScene(const BenchArgs& args) {
  talus::Scene scene = talus::scenes::Ramp40();
  scene.options.dt_s = args.dt_s;
  if (args.tolerance > 0) scene.options.tolerance_m_s = args.tolerance;
  if (args.max_iterations > 0) scene.options.max_iterations = args.max_iterations;
  talus::ParseViscousReading(args.viscous, &scene.options.viscous);
  talus::ParseContactSolveMethod(args.contact_solve, &scene.options.contact_solve);
  talus::ParseSoilDragPoint(args.soil_drag, &scene.options.soil_drag);
  for (int i = 0; i < scene.ground.size(); ++i) {
    talus::GroundParams& p = scene.ground.mutable_params(i);
    talus::ParseGroundModel(args.ground_model, &p.model);
    p.soil_strength_mn_m2 = args.soil_strength;
    p.compaction_drag = args.compaction_drag;
  }
  return scene;
}

// The machine, the build and the scene: the heading of every result.
void PrintSetting(const talus::Scene& scene, const BenchArgs& args) {
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
      "medium_hard; dt %.4f s, tolerance %.1e m/s, at most %d sweeps; viscous term: %s; "
      "contact solve: %s; ground model: %s",
      scene.rock.mass_kg, scene.rock.vertices_m.size(), scene.options.dt_s,
      scene.options.tolerance_m_s, scene.options.max_iterations,
      talus::ToString(scene.options.viscous), talus::ToString(scene.options.contact_solve),
      args.ground_model.c_str());
  if (args.ground_model == "lu2019")
    std::printf(" (M_E %g MN/m^2, C_s %g, drag at %s)", args.soil_strength, args.compaction_drag,
                args.soil_drag.c_str());
  std::printf("\n");
}

// The timed repeats: each one's rate, then the median; returns the last repeat.
Batch RunRepeats(const talus::Scene& scene, const BenchArgs& args) {
  std::vector<double> rates, step_rates;
  Batch last;
  for (int r = 0; r < args.repeats; ++r) {
    last = RunBatch(scene, args.rocks, args.seed, !args.detect_every_step, nullptr);
    rates.push_back(args.rocks / last.wall_s);
    step_rates.push_back(last.steps / last.wall_s);
    std::printf("repeat %d: %d trajectories in %.3f s = %.1f trajectories/s\n", r + 1, args.rocks,
                last.wall_s, rates.back());
  }
  std::printf("\ntrajectories per second (one core, median of %d): %.1f\n", args.repeats,
              Median(rates));
  std::printf("steps per second (median): %.3g\n", Median(step_rates));
  return last;
}

// What a batch's rocks did: accuracy figures, the contact solve's work, the ramp statistics of
// Leine et al. 2021 and the endings.
void PrintBatchStatistics(const Batch& last, int rocks) {
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
  std::printf("flight steps without contact detection (flight windows): %.1f %% of steps\n",
              100.0 * last.flight_steps / last.steps);
  const auto [speed_mean, speed_sd] = MeanAndSd(last.max_speeds_m_s);
  const auto [rotation_mean, rotation_sd] = MeanAndSd(last.rotation_rates_1_s);
  const auto [jump_mean, jump_sd] = MeanAndSd(last.jump_heights_m);
  const auto [time_mean, time_sd] = MeanAndSd(last.travel_times_s);
  const auto [runout_mean, runout_sd] = MeanAndSd(last.runouts_m);
  const auto [energy_mean, energy_sd] = MeanAndSd(last.kinetic_energies_kj);
  int slow = 0;
  for (double v : last.max_speeds_m_s) slow += v < 5;
  std::printf(
      "ramp statistics per rock (mean +- sd; Leine et al. 2021, Table 2, RAMMS::ROCKFALL: max "
      "speed "
      "17.75 +- 7.7 m/s, rotation 4.77 +- 1.9 rot/s, jump height 1.40 +- 1.1 m, kinetic energy "
      "188.03 +- 131.7 kJ):\n"
      "  max speed %.2f +- %.2f m/s (median %.2f); rotation rate (max angular speed / 2 pi) "
      "%.2f +- %.2f rot/s (median %.2f); max jump height %.2f +- %.2f m (median %.2f)\n"
      "  max kinetic energy (translational + rotational) %.1f +- %.1f kJ (median %.1f)\n"
      "  runout %.1f +- %.1f m (median %.1f); travel time %.1f +- %.1f s (median %.1f); "
      "stopped within 5 m %.1f %%; max speed below 5 m/s %.1f %%\n",
      speed_mean, speed_sd, Median(last.max_speeds_m_s), rotation_mean, rotation_sd,
      Median(last.rotation_rates_1_s), jump_mean, jump_sd, Median(last.jump_heights_m),
      energy_mean, energy_sd, Median(last.kinetic_energies_kj), runout_mean,
      runout_sd, Median(last.runouts_m), time_mean, time_sd, Median(last.travel_times_s),
      100.0 * last.stopped_within_5_m / rocks, 100.0 * slow / rocks);
  std::printf("endings:");
  for (const auto& [end, count] : last.endings) std::printf(" %s %d", end.c_str(), count);
  std::printf(
      "\nreference: RAMMS::ROCKFALL 1000 trajectories in 161.5 s = 6.2 trajectories/s "
      "(Leine et al. 2021, Table 1)\n");
}

// The same rocks again, with the per-cell recorder (a separate run: it is not timed).
void PrintCellStatistics(const talus::Scene& scene, const BenchArgs& args) {
  const CellValues cells = RunCellStatistics(scene, args.rocks, args.seed);
  std::printf(
      "\nramp statistics pooled per cell (RAMMS's statistic mode: each rock's maximum in each "
      "%.0f m cell its centre of mass passed, %zu values of %d rocks; mean +- sd (median)):\n",
      scene.terrain.heights().grid.dx_m, cells.speeds_m_s.size(), args.rocks);
  const std::pair<const char*, const std::vector<double>*> pooled[] = {
      {"speed, m/s", &cells.speeds_m_s},
      {"rotation rate, rot/s", &cells.rotation_rates_1_s},
      {"jump height, m", &cells.jump_heights_m},
      {"kinetic energy, kJ", &cells.kinetic_energies_kj}};
  for (const auto& [name, values] : pooled) {
    const auto [mean, sd] = MeanAndSd(*values);
    std::printf("  %-22s %8.2f +- %7.2f (%.2f)\n", name, mean, sd, Median(*values));
  }
}

// The stages' share of a step, in a separate run (the clock calls cost time of their own).
void PrintStageProfile(const talus::Scene& scene, const BenchArgs& args) {
  talus::StageTimes times;
  RunBatch(scene, std::max(1, args.rocks / 4), args.seed, !args.detect_every_step, &times);
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
}

}  // namespace

int RunBenchmark(int argc, char** argv) {
  CLI::App app{"Ramp benchmark: EOTA221 block trajectories down a 40 degree plane, one core"};
  BenchArgs args;
  AddOptions(app, &args);
  CLI11_PARSE(app, argc, argv);
  const talus::Scene scene = MakeScene(args);
  std::string why;
  if (!scene.IsValid(&why)) {
    std::fprintf(stderr, "ramp_bench: %s\n", why.c_str());
    return 1;
  }
  PrintSetting(scene, args);
  PrintBatchStatistics(RunRepeats(scene, args), args.rocks);
  if (args.no_profile) return 0;
  if (!args.no_cells) PrintCellStatistics(scene, args);
  PrintStageProfile(scene, args);
  return 0;
}
