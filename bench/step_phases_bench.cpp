// Benchmark: where a step's error comes from, phase by phase. The scene's rocks run at a fine step;
// every `interval` seconds of each rock's path its state is kept. From each kept state the rock
// then runs a window of `window` seconds twice, at the fine and at the coarse step, each from a
// fresh workspace. The same start, so the comparison is between like phases, before the paths
// part: per class of the start (the centre of mass's speed, and whether the step that ended there
// carried load) the mechanical energy each run lost per kilogram, the difference coarse - fine with
// its standard error, the share of the window's steps that carried load and the mean scar length.
// A class where the coarse step loses less energy than the fine one is where its rocks run further.
// Per class also the highest the centre of mass rose above the terrain after the window's first
// loaded step (the rebound's jump height), fine and coarse - fine. With --from-coarse the starts
// are taken from a run at the coarse step instead: the states the coarse step's own rocks visit.
//
// Landings (starts in flight faster than --landing-speed): the same difference at the end of each
// coarse step from the coarse run's first loaded step on, split into the work of the normal and of
// the tangential percussions (friction and the contact-friction viscous term), with the loaded time
// and the scar of both runs, so that a landing's error can be told apart from the impact's.

#include <CLI/CLI.hpp>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "bench/bench_main.hpp"
#include "ensemble/runner.hpp"
#include "io/scene_file.hpp"
#include "solver/ground.hpp"
#include "solver/kinematics.hpp"
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

double RotationalEnergy(const talus::RockShape& rock, const talus::RockState& s) {
  return 0.5 *
         s.angular_velocity_rad_s.dot(rock.inertia_kg_m2.cwiseProduct(s.angular_velocity_rad_s));
}

// What a run has done since its start, per kg, read at the end of every coarse step.
struct Mark {
  double energy_j_kg = 0;      // mechanical energy change
  double rotational_j_kg = 0;  // rotational kinetic energy change
  // Work of the normal and of the tangential percussions: sum over contacts of P (g- + g+) / 2,
  // g- the contact velocity of the free motion, g+ of the end velocities. Their sum is the
  // percussions' kinetic energy change; the rest of the energy change is the midpoint rule's
  // gravity term, m g dt dv_z / 2 per step, small (printed as "rest").
  double normal_j_kg = 0, tangential_j_kg = 0;
  double loaded_s = 0;  // time in steps (or impact sub-steps) that carried load
  double scar_m = 0;    // the scar at the mark
  std::string pattern;  // per step of this mark: L loaded, . not; l and , for impact sub-steps
};

// One window from a start. False when the rock left the DEM or the state stopped being finite.
struct Window {
  double energy_j_kg = 0, loaded = 0, scar_m = 0;  // energy change; mean loaded share and scar
  // The highest the centre of mass came above the terrain (along its normal) after the window's
  // first loaded step, as the jump height of talus simulate's statistics: the rebound's; read at
  // the end of each step that carried no load.
  double apex_m = 0;
  std::vector<Mark> marks;
  int first_loaded_mark = -1;  // first mark in which the run carried load; -1: never
};

// Adds the work of this (sub-)step's percussions, from `begin` to `end`, to `mark`.
void AddPercussionWork(const talus::RockShape& rock, double dt_s, double gravity_m_s2,
                       const talus::RockState& begin, const talus::RockState& end,
                       const std::vector<talus::Contact>& contacts, Mark& mark) {
  Eigen::Vector3d v_free = begin.velocity_m_s;
  v_free.z() -= dt_s * gravity_m_s2;
  const Eigen::Vector3d w_free =
      talus::FreeRotation(rock.inertia_kg_m2, begin.angular_velocity_rad_s, dt_s);
  for (const talus::Contact& c : contacts) {
    const Eigen::Vector3d before = c.directions.transpose() * v_free + c.arms.transpose() * w_free;
    const Eigen::Vector3d after = c.directions.transpose() * end.velocity_m_s +
                                  c.arms.transpose() * end.angular_velocity_rad_s;
    const Eigen::Vector3d work = 0.5 * c.percussion.cwiseProduct(before + after) / rock.mass_kg;
    mark.normal_j_kg += work.x();
    mark.tangential_j_kg += work.y() + work.z();
  }
}

// One step with its percussions' work. A step taken as impact sub-steps is taken again, from the
// same state and workspace, one sub-step at a time (a scene of dt / substeps without sub-steps:
// the same arithmetic), so that each sub-step's percussions are seen.
bool AccountedStep(const talus::Scene& scene, const talus::Scene& sub, const talus::RockShape& rock,
                   talus::RockState& s, talus::StepWorkspace& workspace, Mark& mark,
                   talus::StepReport* report) {
  const talus::RockState begin = s;
  const talus::StepWorkspace workspace_begin = workspace;
  *report = talus::Step(scene, rock, s, workspace);
  if (report->outside_domain || !s.position_m.allFinite()) return false;
  const double g = scene.options.gravity_m_s2;
  if (report->substeps == 1) {
    AddPercussionWork(rock, scene.options.dt_s, g, begin, s, workspace.contacts, mark);
    mark.pattern += report->loaded ? 'L' : '.';
    mark.loaded_s += report->loaded ? scene.options.dt_s : 0.0;
    return true;
  }
  s = begin;
  workspace = workspace_begin;
  for (int k = 0; k < report->substeps; ++k) {
    const talus::RockState part = s;
    const talus::StepReport r = talus::Step(sub, rock, s, workspace);
    if (r.outside_domain) return false;
    AddPercussionWork(rock, sub.options.dt_s, g, part, s, workspace.contacts, mark);
    mark.pattern += r.loaded ? 'l' : ',';
    mark.loaded_s += r.loaded ? sub.options.dt_s : 0.0;
  }
  return true;
}

bool RunWindow(const talus::Scene& scene, const Start& start, double window_s, double mark_s,
               Window* out) {
  const talus::RockShape& rock = *start.shape;
  talus::StepWorkspace workspace;
  workspace.Reset(rock.vertices_m.size());
  talus::Scene sub = scene;
  sub.options.dt_s = scene.options.dt_s / std::max(1, scene.options.impact_substeps);
  sub.options.impact_substeps = 1;
  talus::RockState s = start.state;
  const long steps = std::lround(window_s / scene.options.dt_s);
  const long per_mark = std::max(1L, std::lround(mark_s / scene.options.dt_s));
  const double e0 = MechanicalEnergy(scene, rock, start.state);
  const double r0 = RotationalEnergy(rock, start.state);
  Window w;
  Mark running;
  double loaded = 0, scar = 0;
  for (long k = 0; k < steps; ++k) {
    talus::StepReport r;
    if (!AccountedStep(scene, sub, rock, s, workspace, running, &r)) return false;
    loaded += r.loaded;
    scar += s.scar_m;
    if (r.loaded && w.first_loaded_mark < 0) w.first_loaded_mark = static_cast<int>(k / per_mark);
    talus::TerrainSample under;
    if (w.first_loaded_mark >= 0 && !r.loaded &&
        scene.terrain.Sample(s.position_m.x(), s.position_m.y(), &under))
      w.apex_m = std::max(w.apex_m, (s.position_m.z() - under.height_m) * under.normal.z());
    if ((k + 1) % per_mark == 0) {
      running.energy_j_kg = (MechanicalEnergy(scene, rock, s) - e0) / rock.mass_kg;
      running.rotational_j_kg = (RotationalEnergy(rock, s) - r0) / rock.mass_kg;
      running.scar_m = s.scar_m;
      w.marks.push_back(running);
      running.pattern.clear();
    }
  }
  w.energy_j_kg = (MechanicalEnergy(scene, rock, s) - e0) / rock.mass_kg;
  w.loaded = loaded / steps;
  w.scar_m = scar / steps;
  *out = std::move(w);
  return true;
}

// Sum and sum of squares of a difference, for its mean and standard error.
struct Moments {
  long n = 0;
  double sum = 0, sum2 = 0;
  void Add(double d) {
    ++n;
    sum += d;
    sum2 += d * d;
  }
  double Mean() const { return sum / n; }
  double StandardError() const {
    const double mean = Mean();
    return n > 1 ? std::sqrt(std::max(0.0, sum2 / n - mean * mean) / (n - 1)) : NAN;
  }
  // "mean ± se", flagged when the mean is beyond two standard errors.
  std::string Format() const {
    char text[96];
    const double mean = Mean(), se = StandardError();
    std::snprintf(text, sizeof text, "%+.4f ± %.4f%s", mean, se,
                  std::abs(mean) > std::max(2 * se, 1e-9) ? " **≠**" : "");
    return text;
  }
};

// Landings: coarse - fine at marks relative to the coarse run's first loaded mark.
struct Landing {
  static constexpr std::array<int, 9> kOffsets = {-1, 0, 1, 2, 3, 5, 10, 20, 40};
  struct Row {
    Moments energy, rotational, normal, tangential;
    double fine_energy = 0, loaded_fine = 0, loaded_coarse = 0, scar_fine = 0, scar_coarse = 0;
  };
  std::array<Row, kOffsets.size()> rows;
  long later_sum = 0, later_n = 0;  // the fine run's first loaded mark minus the coarse run's

  void Add(const Window& f, const Window& c) {
    for (std::size_t i = 0; i < kOffsets.size(); ++i) {
      const long j = c.first_loaded_mark + kOffsets[i];
      if (j < 0 || j >= static_cast<long>(std::min(c.marks.size(), f.marks.size()))) continue;
      const Mark &fm = f.marks[j], &cm = c.marks[j];
      Row& row = rows[i];
      row.energy.Add(cm.energy_j_kg - fm.energy_j_kg);
      row.rotational.Add(cm.rotational_j_kg - fm.rotational_j_kg);
      row.normal.Add(cm.normal_j_kg - fm.normal_j_kg);
      row.tangential.Add(cm.tangential_j_kg - fm.tangential_j_kg);
      row.fine_energy += fm.energy_j_kg;
      row.loaded_fine += fm.loaded_s;
      row.loaded_coarse += cm.loaded_s;
      row.scar_fine += fm.scar_m;
      row.scar_coarse += cm.scar_m;
    }
    if (f.first_loaded_mark >= 0) {
      later_sum += f.first_loaded_mark - c.first_loaded_mark;
      ++later_n;
    }
  }

  void Print(double landing_speed, bool same_mark) const {
    std::printf(
        "\nLandings: starts not loaded, faster than %g m/s%s. Coarse - fine since the start, at "
        "the end of the coarse step k steps after its first loaded one (k = 0: that step): the "
        "energy change, of it the rotational kinetic energy's, the work of the normal and of the "
        "tangential percussions, and the rest (the midpoint rule's gravity term); the loaded time "
        "and the scar of both runs. The fine run's first loaded step is %.2f coarse steps later "
        "on average.\n\n"
        "| k | windows | energy change, fine (J/kg) | coarse - fine (J/kg) | rotational | "
        "normal work | tangential work | rest | loaded time, fine / coarse (ms) | scar, fine / "
        "coarse (m) |\n|---|---|---|---|---|---|---|---|---|---|\n",
        landing_speed,
        same_mark ? ", and whose fine run first carries load in the same coarse step" : "",
        later_n ? static_cast<double>(later_sum) / later_n : NAN);
    for (std::size_t i = 0; i < kOffsets.size(); ++i) {
      const Row& row = rows[i];
      const long n = row.energy.n;
      if (n == 0) continue;
      const double rest = row.energy.Mean() - row.normal.Mean() - row.tangential.Mean();
      std::printf("| %d | %ld | %.4f | %s | %s | %s | %s | %+.4f | %.2f / %.2f | %.4f / %.4f |\n",
                  kOffsets[i], n, row.fine_energy / n, row.energy.Format().c_str(),
                  row.rotational.Format().c_str(), row.normal.Format().c_str(),
                  row.tangential.Format().c_str(), rest, 1e3 * row.loaded_fine / n,
                  1e3 * row.loaded_coarse / n, row.scar_fine / n, row.scar_coarse / n);
    }
  }
};

struct Tally {
  long n = 0;
  double fine = 0, coarse = 0;
  Moments diff, apex;
  double loaded_fine = 0, loaded_coarse = 0, scar_fine = 0, scar_coarse = 0, apex_fine = 0;
  void Add(const Window& f, const Window& c) {
    ++n;
    apex.Add(c.apex_m - f.apex_m);
    apex_fine += f.apex_m;
    fine += f.energy_j_kg;
    coarse += c.energy_j_kg;
    diff.Add(c.energy_j_kg - f.energy_j_kg);
    loaded_fine += f.loaded;
    loaded_coarse += c.loaded;
    scar_fine += f.scar_m;
    scar_coarse += c.scar_m;
  }
};

// --ground KEY=VALUE: sets a ground field on every category. False, with a message, when `set` is
// not KEY=VALUE with a ground key and a number.
bool SetGroundField(const std::string& set, talus::GroundTable& ground) {
  const std::size_t eq = set.find('=');
  const talus::GroundFieldInfo* field =
      eq == std::string::npos ? nullptr : talus::FindGroundField(set.substr(0, eq));
  char* end = nullptr;
  const double value = field ? std::strtod(set.c_str() + eq + 1, &end) : NAN;
  if (!field || end == set.c_str() + eq + 1 || *end != '\0' || !std::isfinite(value)) {
    std::fprintf(stderr, "--ground %s: not KEY=VALUE with a [ground.<name>] key and a number\n",
                 set.c_str());
    return false;
  }
  for (int g = 0; g < ground.size(); ++g) ground.mutable_params(g).*(field->member) = value;
  return true;
}

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
  double landing_speed = 10;
  app.add_option("--landing-speed", landing_speed,
                 "Landings table: starts not loaded and faster than this, m/s");
  bool same_mark = false;
  app.add_flag("--same-landing", same_mark,
               "Landings table: only windows whose two runs first carry load in the same coarse "
               "step");
  int show = 0;
  app.add_option("--show-landings", show,
                 "Print the loaded steps of the first N landings (fine and coarse, per coarse "
                 "step from the coarse run's first loaded one)");
  bool from_coarse = false;
  app.add_flag("--from-coarse", from_coarse,
               "Take the starts from a run at the coarse step (default: at the fine step)");
  std::vector<std::string> ground_sets;
  app.add_option("--ground", ground_sets,
                 "KEY=VALUE set on every ground category, e.g. nu=0 (a [ground.<name>] key)");
  CLI11_PARSE(app, argc, argv);
  PrintMachine(argc, argv);

  talus::io::SceneFile file = talus::io::LoadScene(scene_path);
  for (const std::string& set : ground_sets)
    if (!SetGroundField(set, file.scene.ground)) return 2;
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
  talus::ensemble::RunEnsemble(from_coarse ? coarse : fine, release, options, nullptr);

  // Classes: speed of the centre of mass at the start (upper bounds, m/s), and whether the step
  // that ended there carried load; each start also counts in its speed's "all".
  constexpr std::array<double, 5> kSpeeds = {0.5, 2, 5, 10, INFINITY};
  std::map<std::pair<int, int>, Tally> tallies;
  Landing landing;
  std::string shown;
  long left = 0;
  for (const Start& start : starts) {
    Window f, c;
    if (!RunWindow(fine, start, window_s, coarse_s, &f) ||
        !RunWindow(coarse, start, window_s, coarse_s, &c)) {
      ++left;
      continue;
    }
    int bin = 0;
    while (start.state.velocity_m_s.norm() > kSpeeds[bin]) ++bin;
    tallies[{bin, start.loaded ? 1 : 0}].Add(f, c);
    tallies[{bin, 2}].Add(f, c);
    if (start.loaded || start.state.velocity_m_s.norm() <= landing_speed ||
        c.first_loaded_mark < 0 || (same_mark && f.first_loaded_mark != c.first_loaded_mark))
      continue;
    landing.Add(f, c);
    if (show-- > 0) {
      std::string fine_steps, coarse_steps;
      for (int j = c.first_loaded_mark;
           j < std::min<int>(c.first_loaded_mark + 4, static_cast<int>(c.marks.size())); ++j) {
        fine_steps += f.marks[j].pattern + "|";
        coarse_steps += c.marks[j].pattern + "|";
      }
      shown += "    fine " + fine_steps + "  coarse " + coarse_steps + "\n";
    }
  }
  std::printf(
      "%zu starts from the run at %g s (%ld left the DEM within a window); windows of %g s at %g "
      "and %g s\n\n",
      starts.size(), from_coarse ? coarse_s : fine_s, left, window_s, fine_s, coarse_s);
  std::printf(
      "| speed (m/s) | start | windows | energy change, fine (J/kg) | coarse (J/kg) | "
      "coarse - fine (J/kg) | loaded steps, fine | coarse | mean scar, fine (m) | coarse (m) | "
      "highest centre above the terrain, fine (m) | coarse - fine (m) |\n"
      "|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (const auto& [key, t] : tallies) {
    const double low = key.first == 0 ? 0 : kSpeeds[key.first - 1];
    std::printf("| %g-%g | %s | %ld | %.4f | %.4f | %s | %.3f | %.3f | %.4f | %.4f | %.4f | %s |\n",
                low, kSpeeds[key.first],
                key.second == 2 ? "all"
                : key.second    ? "loaded"
                                : "not loaded",
                t.n, t.fine / t.n, t.coarse / t.n, t.diff.Format().c_str(), t.loaded_fine / t.n,
                t.loaded_coarse / t.n, t.scar_fine / t.n, t.scar_coarse / t.n, t.apex_fine / t.n,
                t.apex.Format().c_str());
  }
  landing.Print(landing_speed, same_mark);
  if (!shown.empty())
    std::printf(
        "\nLoaded steps of the first landings, per coarse step (|) from the coarse run's first "
        "loaded one: L loaded, . not; l and , for the sub-steps of a step taken as impact "
        "sub-steps.\n\n%s",
        shown.c_str());
  return 0;
}
