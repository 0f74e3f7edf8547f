// Flight windows: a rock run with them must give the same results, bit for bit, as with contact
// detection in every step; within a window it must fly the closed-form parabola.

#include "solver/flight.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <string_view>
#include <vector>

#include "common/sha256.hpp"
#include "scenes/scenes.hpp"
#include "solver/random.hpp"
#include "solver/shapes.hpp"
#include "solver/simulate.hpp"

namespace talus {
namespace {

constexpr double kG = 9.81;
const GroundParams kHard{0.55, 2.0, 185, 3.0, 0.4};

// Everything an observer sees, step by step, folded into one SHA-256 hash of the numbers' bytes
// (the StepReport's `clear` aside: a flight step reports clear where the full step may have tested
// vertices).
class TraceHash : public StepObserver {
 public:
  void OnStep(const RockState& s, const StepReport& r, const TerrainSample& g) override {
    Add(s.position_m.data(), 3);
    Add(s.orientation.coeffs().data(), 4);
    Add(s.velocity_m_s.data(), 3);
    Add(s.angular_velocity_rad_s.data(), 3);
    Add(&s.scar_m, 1);
    Add(&s.time_s, 1);
    Add(&g.height_m, 1);
    Add(g.normal.data(), 3);
    const double report[] = {double(r.contacts), double(r.iterations), double(r.converged),
                             double(r.loaded), double(r.outside_domain)};
    Add(report, 5);
    ++steps;
  }
  Sha256 hash;
  long steps = 0;

 private:
  void Add(const double* v, int n) {
    hash.Add(std::string_view(reinterpret_cast<const char*>(v), sizeof(double) * n));
  }
};

struct Run {
  RockResult result;
  TraceHash trace;
};

Run RunRock(const Scene& scene, const RockState& start, bool flight_windows) {
  Run run;
  SimulationWorkspace ws;
  ws.flight_windows = flight_windows;
  run.result = SimulateRock(scene, start, ws, &run.trace);
  return run;
}

// Runs the rock both ways and expects the same results bit for bit; returns the flight steps.
long ExpectSameBothWays(const Scene& scene, const RockState& start, const char* what, int rock) {
  const Run every = RunRock(scene, start, false);
  const Run windows = RunRock(scene, start, true);
  const RockResult& a = every.result;
  const RockResult& b = windows.result;
  EXPECT_EQ(a.end, b.end) << what << " rock " << rock;
  EXPECT_EQ(a.steps, b.steps) << what << " rock " << rock;
  EXPECT_EQ(every.trace.hash.HexDigest(), windows.trace.hash.HexDigest())
      << what << " rock " << rock;
  EXPECT_EQ(a.final_state.position_m, b.final_state.position_m) << what << " rock " << rock;
  EXPECT_EQ(a.final_state.orientation.coeffs(), b.final_state.orientation.coeffs())
      << what << " rock " << rock;
  EXPECT_EQ(a.final_state.velocity_m_s, b.final_state.velocity_m_s) << what << " rock " << rock;
  EXPECT_EQ(a.final_state.angular_velocity_rad_s, b.final_state.angular_velocity_rad_s)
      << what << " rock " << rock;
  EXPECT_EQ(a.final_state.scar_m, b.final_state.scar_m) << what << " rock " << rock;
  EXPECT_EQ(a.travel_time_s, b.travel_time_s) << what << " rock " << rock;
  EXPECT_EQ(a.runout_m, b.runout_m) << what << " rock " << rock;
  EXPECT_EQ(a.path_length_m, b.path_length_m) << what << " rock " << rock;
  EXPECT_EQ(a.max_displacement_m, b.max_displacement_m) << what << " rock " << rock;
  EXPECT_EQ(a.max_speed_m_s, b.max_speed_m_s) << what << " rock " << rock;
  EXPECT_EQ(a.max_kinetic_energy_j, b.max_kinetic_energy_j) << what << " rock " << rock;
  EXPECT_EQ(a.max_jump_height_m, b.max_jump_height_m) << what << " rock " << rock;
  EXPECT_EQ(a.max_angular_speed_rad_s, b.max_angular_speed_rad_s) << what << " rock " << rock;
  EXPECT_EQ(a.max_scar_m, b.max_scar_m) << what << " rock " << rock;
  EXPECT_EQ(a.contact_steps, b.contact_steps) << what << " rock " << rock;
  EXPECT_EQ(a.solver_iterations, b.solver_iterations) << what << " rock " << rock;
  EXPECT_EQ(a.unconverged_steps, b.unconverged_steps) << what << " rock " << rock;
  EXPECT_EQ(a.flight_steps, 0) << what << " rock " << rock;
  return b.flight_steps;
}

TEST(FlightWindows, RampRocksAreBitIdenticalToDetectionInEveryStep) {
  // The benchmark ramp under both readings of the viscous term, 8 rocks each. What the comparison
  // covers: at least 2000 steps taken in flight windows, compared bit for bit, per reading.
  // Measured: 4754 of 95 722 steps under contact friction, 34 418 of 133 605 under the
  // centre-of-mass drag (under contact_solve = "gauss_seidel": 18 132 of 100 663 and 25 109 of
  // 191 026; eight rocks' shares vary with their paths: over the bench's 200 rocks the windows are
  // 16.8 % of the steps, and 15.8 % under "gauss_seidel").
  for (ViscousReading reading : {ViscousReading::kContactFriction, ViscousReading::kCentreOfMass}) {
    Scene scene = scenes::Ramp40();
    scene.options.viscous = reading;
    long flight = 0, steps = 0;
    for (int rock = 0; rock < 8; ++rock) {
      const RockState start = scenes::Ramp40Release(scene, 1, rock);
      flight += ExpectSameBothWays(scene, start, ToString(reading), rock);
      steps += RunRock(scene, start, false).result.steps;
    }
    std::printf("%s: %ld flight steps of %ld\n", ToString(reading), flight, steps);
    EXPECT_GT(flight, 2000) << ToString(reading);
  }
}

// A rough slope over a cliff band: 300 x 300 m, 2 m cells, 35 degrees with bumps (waves of
// +-0.8 m and up to 1.05 m of node noise), a 25 m step at x = 120 m, a nodata hole of 8 m radius
// and a flat runout from x = 220 m to the DEM's edge.
Scene RoughCliff(const RockShape& rock) {
  Scene scene = scenes::Incline(0, rock, kHard, 300, 2);
  Heightfield hf = scene.terrain.heights();
  const GridGeometry& g = hf.grid;
  for (int j = 0; j < g.ny; ++j)
    for (int i = 0; i < g.nx; ++i) {
      const double x = g.x0_m + i * g.dx_m, y = g.y0_m + j * g.dy_m;
      double z = std::max(0.0, 220 - x) * std::tan(35 * M_PI / 180);
      z += x < 120 ? 25 : 0;
      z += 0.8 * std::sin(0.9 * x) * std::cos(0.6 * y) + 0.35 * ((i * 7 + j * 11) % 4);
      const bool hole = std::hypot(x - 170, y - 20) < 8;
      hf.z_m[j * g.nx + i] = hole ? std::numeric_limits<double>::quiet_NaN() : z;
    }
  scene.terrain = Terrain(hf, scene.terrain.default_ground());
  scene.options.max_time_s = 40;
  return scene;
}

// Releases on the rough slope: random orientation, spin and velocity (some thrown high), from
// (seed, rock) only.
RockState RoughRelease(const Scene& scene, int rock) {
  RockRandom random(11, rock);
  RockState s;
  s.orientation = random.Orientation();
  const double x = 20 + 60 * random.Uniform(), y = -40 + 80 * random.Uniform();
  double h = 0;
  scene.terrain.Height(x, y, &h);
  s.position_m = {x, y, h + 1 + 12 * random.Uniform()};
  s.velocity_m_s = {25 * random.Uniform(), 16 * (random.Uniform() - 0.5), 10 * random.Uniform()};
  s.angular_velocity_rad_s = {10 * (random.Uniform() - 0.5), 10 * (random.Uniform() - 0.5),
                              10 * (random.Uniform() - 0.5)};
  RaiseAboveTerrain(scene, s);
  return s;
}

TEST(FlightWindows, RoughTerrainRocksAreBitIdenticalToDetectionInEveryStep) {
  // 12 EOTA221 blocks down the rough cliff, once plain and once with a 3 m drag layer: jumps off
  // the cliff, landings on bumps, the nodata hole and the DEM's edge (measured: of the 12, 5
  // leave the domain plain, 1 with the drag layer).
  for (bool drag : {false, true}) {
    Scene scene = RoughCliff(scenes::Eota221());
    if (drag) {
      GroundParams layer = kHard;
      layer.drag_height_m = 3;
      layer.drag_translational_1_s = 0.5;
      layer.drag_rotational_1_s = 1;
      scene.ground.mutable_params(scene.terrain.default_ground()) = layer;
    }
    long flight = 0, left = 0;
    for (int rock = 0; rock < 12; ++rock) {
      const RockState start = RoughRelease(scene, rock);
      flight += ExpectSameBothWays(scene, start, drag ? "drag layer" : "rough", rock);
      left += RunRock(scene, start, true).result.end == EndReason::kLeftDomain;
    }
    EXPECT_GT(flight, 0) << (drag ? "drag layer" : "rough");
    EXPECT_GT(left, 0) << (drag ? "drag layer" : "rough");
  }
}

TEST(FlightWindows, LeavingTheDemOrReachingNodataDuringAFlightEndsAtTheSameStep) {
  // Thrown high and fast towards the DEM's far edge, its side, and over the nodata hole.
  const Scene scene = RoughCliff(MakeRockShape(MakeBox(1, 0.8, 0.5), 2700));
  struct Throw {
    Eigen::Vector3d position, velocity;
  };
  const Throw throws[] = {
      {{200, 0, 60}, {30, 0, 8}}, {{150, 120, 60}, {0, 25, 5}}, {{150, 20, 60}, {20, 0, -3}}};
  for (int k = 0; k < 3; ++k) {
    RockState s;
    s.position_m = throws[k].position;
    s.velocity_m_s = throws[k].velocity;
    s.angular_velocity_rad_s = {3, -2, 1};
    EXPECT_GT(ExpectSameBothWays(scene, s, "throw", k), 50) << k;
    EXPECT_EQ(RunRock(scene, s, true).result.end, EndReason::kLeftDomain) << k;
  }
}

// Records step ends and the first step with a contact.
class FlightLog : public StepObserver {
 public:
  void OnStep(const RockState& s, const StepReport& r, const TerrainSample&) override {
    if (landing_time_s >= 0) return;
    if (r.contacts > 0) {
      landing_time_s = s.time_s;
      landing = s.position_m;
      return;
    }
    states.push_back(s);
  }
  std::vector<RockState> states;  // up to the landing
  double landing_time_s = -1;
  Eigen::Vector3d landing;
};

TEST(FlightWindows, RockThrownHighFliesTheParabolaAndLandsWhereTheClosedFormSays) {
  // A 1 x 1 x 0.5 m box, level and without spin, thrown from 30 m above flat ground at
  // (8, 3, 5) m/s. The midpoint scheme's step ends lie on the parabola r0 + v0 t - g t^2 / 2
  // (trapezoidal rule on a velocity linear in time): tolerance 1e-9 m, round-off over ~1000
  // steps. Its lowest face reaches the ground at t* = (vz + sqrt(vz^2 + 2 g (z0 - 0.25))) / g;
  // the first contact step (closed or predicted at the midpoint) ends within 2 steps of t*
  // (prediction looks one step ahead of the midpoint; stated resolution 2 dt = 4 ms), where the
  // centre is within 2 steps of travel of the closed form.
  const Scene scene = scenes::Incline(0, MakeRockShape(MakeBox(1, 1, 0.5), 2700), kHard);
  const double dt = scene.options.dt_s;
  RockState start;
  start.position_m = {20, 0, 30};
  start.velocity_m_s = {8, 3, 5};
  FlightLog log;
  SimulationWorkspace ws;
  const RockResult r = SimulateRock(scene, start, ws, &log);
  ASSERT_GT(log.landing_time_s, 0);
  const Eigen::Vector3d v0 = start.velocity_m_s;
  for (const RockState& s : log.states) {
    const double t = s.time_s;
    const Eigen::Vector3d closed =
        start.position_m + t * v0 - 0.5 * kG * t * t * Eigen::Vector3d::UnitZ();
    ASSERT_LT((s.position_m - closed).norm(), 1e-9) << "t = " << t;
    ASSERT_NEAR(s.velocity_m_s.z(), v0.z() - kG * t, 1e-9) << "t = " << t;
  }
  const double t_land =
      (v0.z() + std::sqrt(v0.z() * v0.z() + 2 * kG * (start.position_m.z() - 0.25))) / kG;
  EXPECT_NEAR(log.landing_time_s, t_land, 2 * dt);
  const Eigen::Vector3d land = start.position_m + t_land * v0;
  EXPECT_NEAR(log.landing.x(), land.x(), 2 * dt * v0.x());
  EXPECT_NEAR(log.landing.y(), land.y(), 2 * dt * v0.y());
  // The apex, z0 + vz^2 / (2 g), is the largest jump height to the step's resolution
  // (g dt^2 / 8 = 5e-6 m).
  EXPECT_NEAR(r.max_jump_height_m, 30 + v0.z() * v0.z() / (2 * kG), 1e-5);
  // Most of the flight took the lean path: all but the steps where the bounding sphere (radius
  // 0.75 m) is within reach of the ground (measured: 1501 of the 1511 steps before the landing,
  // which came at 3.0240 s for t* = 3.0246 s).
  EXPECT_GT(r.flight_steps, 0.9 * static_cast<double>(log.states.size()));
}

TEST(FlightWindows, NoStepOfAWindowFindsAContact) {
  // ClearFlightSteps from random states above the rough cliff, then its steps taken with full
  // detection: none may find a contact or leave the domain.
  const Scene scene = RoughCliff(scenes::Eota221());
  long total = 0;
  for (int k = 0; k < 200; ++k) {
    RockRandom random(5, k);
    RockState s;
    s.orientation = random.Orientation();
    const double x = 10 + 270 * random.Uniform(), y = -55 + 110 * random.Uniform();
    double h = 0;
    if (!scene.terrain.Height(x, y, &h)) continue;
    s.position_m = {x, y, h + 0.5 + 6 * random.Uniform()};
    s.velocity_m_s = {40 * (random.Uniform() - 0.5), 40 * (random.Uniform() - 0.5),
                      30 * (random.Uniform() - 0.5)};
    s.angular_velocity_rad_s = {30 * (random.Uniform() - 0.5), 30 * (random.Uniform() - 0.5),
                                30 * (random.Uniform() - 0.5)};
    const int clear = ClearFlightSteps(scene, scene.rock, s, 500);
    total += clear;
    StepWorkspace ws;
    ws.Reset(scene.rock.vertices_m.size());
    for (int step = 0; step < clear; ++step) {
      const StepReport r = Step(scene, s, ws);
      ASSERT_EQ(r.contacts, 0) << "state " << k << ", step " << step << " of " << clear;
      ASSERT_TRUE(ws.contacts.empty()) << "state " << k << ", step " << step << " of " << clear;
      ASSERT_FALSE(r.outside_domain) << "state " << k << ", step " << step << " of " << clear;
    }
  }
  EXPECT_GT(total, 1000);  // measured: 24 824 steps in windows
}

}  // namespace
}  // namespace talus
