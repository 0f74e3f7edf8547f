// Benchmark: what the steps of a scene's rocks are, one core, no outputs. Prints the share of steps
// with a contact, of contact-free steps, of steps that needed no vertex test (bounding sphere clear
// of the terrain, or in a flight window) and of steps taken in flight windows (solver/flight.hpp),
// and the wall time with and without flight windows (the same rocks, bit for bit), alternated.
// Then where the contact solve's work is: the contact steps by number of contacts with their
// Gauss-Seidel sweeps, the steps and sweeps of the rocks by their ending, and a per-stage time
// profile (a separate run, since the clock calls cost time of their own).

#include <CLI/CLI.hpp>
#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include "bench/bench_main.hpp"
#include "io/scene_file.hpp"
#include "solver/simulate.hpp"

namespace {

// Steps and sweeps of a group of steps (a number of contacts, or the rocks of one ending).
struct Tally {
  long steps = 0, contact_steps = 0, sweeps = 0, unconverged = 0;
  void Add(const Tally& t) {
    steps += t.steps;
    contact_steps += t.contact_steps;
    sweeps += t.sweeps;
    unconverged += t.unconverged;
  }
};

// Contact steps are grouped by StepReport::contacts: 0 (only predicted contacts, none loaded,
// still a solve), 1, 2, 3, 4 or more.
constexpr int kContactGroups = 5;

class StepKinds : public talus::StepObserver {
 public:
  void OnStep(const talus::RockState&, const talus::StepReport& step,
              const talus::TerrainSample&) override {
    ++steps;
    contact += step.contacts > 0;
    clear += step.clear;
    ++rock.steps;
    if (step.iterations == 0) return;
    Tally& group = by_contacts[std::min(step.contacts, kContactGroups - 1)];
    for (Tally* t : {&group, &rock}) {
      t->contact_steps += 1;
      t->sweeps += step.iterations;
      t->unconverged += !step.converged;
    }
  }
  // Files the finished rock's steps under its ending.
  void EndRock(talus::EndReason end) {
    by_end[static_cast<int>(end)].Add(rock);
    ++rocks_by_end[static_cast<int>(end)];
    rock = Tally{};
  }
  long steps = 0, contact = 0, clear = 0;
  std::array<Tally, kContactGroups> by_contacts{};
  std::array<Tally, talus::kEndReasons> by_end{};  // indexed by talus::EndReason
  std::array<int, talus::kEndReasons> rocks_by_end{};

 private:
  Tally rock;
};

struct Run {
  StepKinds kinds;
  long flight_steps = 0;
  double wall_s = 0;
};

Run RunRocks(const talus::io::SceneFile& file, long rocks, bool flight_windows,
             talus::StageTimes* times = nullptr) {
  Run run;
  talus::SimulationWorkspace workspace;
  workspace.flight_windows = flight_windows;
  workspace.stage_times = times;
  const auto t0 = std::chrono::steady_clock::now();
  for (long k = 0; k < rocks; ++k) {
    const talus::ensemble::ReleasedRock rock =
        talus::ensemble::Release(file.scene, file.release, k);
    const talus::RockResult result =
        talus::SimulateRock(file.scene, *rock.shape, rock.start, workspace, &run.kinds);
    run.flight_steps += result.flight_steps;
    run.kinds.EndRock(result.end);
  }
  run.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return run;
}

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

double Ratio(long a, long b) { return b ? static_cast<double>(a) / static_cast<double>(b) : 0.0; }

// One row per group: share of all steps, of contact steps, sweeps per contact step, share of all
// sweeps, unconverged steps.
void PrintTally(const char* name, const Tally& t, const StepKinds& all, long all_contact_steps,
                long all_sweeps) {
  std::printf("| %s | %.1f %% | %.1f %% | %.2f | %.1f %% | %ld |\n", name,
              100 * Ratio(t.steps, all.steps), 100 * Ratio(t.contact_steps, all_contact_steps),
              Ratio(t.sweeps, t.contact_steps), 100 * Ratio(t.sweeps, all_sweeps), t.unconverged);
}

void PrintContactWork(const StepKinds& k) {
  Tally solved;
  for (const Tally& t : k.by_contacts) solved.Add(t);
  std::printf(
      "\ncontact solves: %.1f %% of steps, %.2f sweeps per solve, %ld unconverged\n"
      "| group | steps | contact solves | sweeps per solve | sweeps | unconverged |\n"
      "|---|---|---|---|---|---|\n",
      100 * Ratio(solved.contact_steps, k.steps), Ratio(solved.sweeps, solved.contact_steps),
      solved.unconverged);
  const char* names[kContactGroups] = {"0 contacts (predicted, unloaded)", "1 contact",
                                       "2 contacts", "3 contacts", "4 or more contacts"};
  for (int g = 0; g < kContactGroups; ++g) {
    Tally t = k.by_contacts[g];
    t.steps = t.contact_steps;  // a group's steps are its solves
    PrintTally(names[g], t, k, solved.contact_steps, solved.sweeps);
  }
  for (talus::EndReason end :
       {talus::EndReason::kRest, talus::EndReason::kLeftDomain, talus::EndReason::kMaxTime,
        talus::EndReason::kFailed, talus::EndReason::kBarrier}) {
    const int e = static_cast<int>(end);
    if (k.rocks_by_end[e] == 0) continue;
    const std::string name = std::string("rocks ending ") + talus::ToString(end) + " (" +
                             std::to_string(k.rocks_by_end[e]) + ")";
    PrintTally(name.c_str(), k.by_end[e], k, solved.contact_steps, solved.sweeps);
  }
}

void PrintStageProfile(const talus::StageTimes& t) {
  const double total = t.midpoint_s + t.free_rotation_s + t.contacts_s + t.solve_s + t.end_s;
  std::printf("\nstage profile with flight windows (%ld steps, %.0f ns per step timed):\n", t.steps,
              1e9 * total / static_cast<double>(t.steps));
  const std::pair<const char*, double> stages[] = {{"midpoint drift", t.midpoint_s},
                                                   {"free rotation", t.free_rotation_s},
                                                   {"contact detection", t.contacts_s},
                                                   {"contact solve", t.solve_s},
                                                   {"end drift + scar", t.end_s}};
  for (const auto& [name, seconds] : stages)
    std::printf("  %-18s %5.1f %%  %5.0f ns per step\n", name, 100 * seconds / total,
                1e9 * seconds / static_cast<double>(t.steps));
}

}  // namespace

int RunBenchmark(int argc, char** argv) {
  CLI::App app{"Step kinds: contact, flight, flight windows, over a scene's rocks on one core"};
  std::string scene_path;
  long rocks = 0;
  app.add_option("scene", scene_path, "Scene file (TOML)")->required();
  app.add_option("--rocks", rocks, "Rocks to run (default: the scene's)");
  int repeats = 3;
  app.add_option("--repeats", repeats, "Runs of each way (the median is reported)")
      ->check(CLI::PositiveNumber);
  double tolerance_m_s = 0;
  app.add_option("--tolerance", tolerance_m_s,
                 "Contact solver tolerance, m/s (default: the scene's)")
      ->check(CLI::PositiveNumber);
  bool no_profile = false;
  app.add_flag("--no-profile", no_profile, "Skip the per-stage time profile");
  CLI11_PARSE(app, argc, argv);
  talus::io::SceneFile file = talus::io::LoadScene(scene_path);
  if (tolerance_m_s > 0) file.scene.options.tolerance_m_s = tolerance_m_s;
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
  std::printf(
      "%s, %ld rocks, %ld steps, tolerance %.0e m/s: %.1f %% with a contact, %.1f %% without\n",
      scene_path.c_str(), rocks, k.steps, file.scene.options.tolerance_m_s, 100 * k.contact / steps,
      100 * (k.steps - k.contact) / steps);
  std::printf("no vertex test: %.1f %% with flight windows, %.1f %% with detection in every step\n",
              100 * k.clear / steps, 100 * every.kinds.clear / steps);
  std::printf("flight windows: %.1f %% of the steps\n", 100 * windows.flight_steps / steps);
  std::printf(
      "wall time, one core (median of %d): %.2f s with flight windows, %.2f s with detection in "
      "every step\n",
      repeats, Median(windows_s), Median(every_s));
  PrintContactWork(k);
  if (no_profile) return 0;
  talus::StageTimes times;
  RunRocks(file, rocks, true, &times);
  PrintStageProfile(times);
  return 0;
}
