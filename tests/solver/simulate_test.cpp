// Endings of a rock's run and the statistics SimulateRock reports.

#include "solver/simulate.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>

#include "scenes/scenes.hpp"
#include "solver/random.hpp"
#include "solver/shapes.hpp"
#include "tests/solver/energy_bound.hpp"

namespace talus {
namespace {

Scene FlatScene() {
  return scenes::Incline(0, MakeRockShape(MakeBox(1, 1, 0.5), 2700),
                         GroundParams{0.5, 0.5, 150, 2, 0});
}

TEST(Simulate, FreeFallStatisticsMatchClosedForm) {
  // Drop from 20 m over flat ground; the step just before impact has v = g t, and the largest
  // jump height is the release height. Max kinetic energy m g h to 1 % (discrete impact step).
  Scene scene = FlatScene();
  SimulationWorkspace ws;
  RockState s;
  s.position_m = {50, 0, 20.25};
  const RockResult r = SimulateRock(scene, s, ws);
  EXPECT_EQ(r.end, EndReason::kRest);
  EXPECT_NEAR(r.max_jump_height_m, 20.25, 1e-9);
  EXPECT_NEAR(r.max_kinetic_energy_j, scene.rock.mass_kg * 9.81 * 20,
              0.01 * scene.rock.mass_kg * 9.81 * 20);
  EXPECT_NEAR(r.max_speed_m_s, std::sqrt(2 * 9.81 * 20), 0.01 * std::sqrt(2 * 9.81 * 20));
  EXPECT_LT(r.path_length_m, 1e-6);
  EXPECT_EQ(r.unconverged_steps, 0);
}

TEST(Simulate, LeavingTheDemEndsAsLeftDomain) {
  Scene scene = FlatScene();
  SimulationWorkspace ws;
  RockState s;
  s.position_m = {190, 0, 5};
  s.velocity_m_s = {20, 0, 0};
  const RockResult r = SimulateRock(scene, s, ws);
  EXPECT_EQ(r.end, EndReason::kLeftDomain);
  EXPECT_LT(r.travel_time_s, 1.0);
}

TEST(Simulate, NodataEndsAsLeftDomain) {
  Scene scene = FlatScene();
  Heightfield hf = scene.terrain.heights();
  for (int j = 0; j < hf.grid.ny; ++j)
    for (int i = 21; i < hf.grid.nx; ++i)
      hf.z_m[j * hf.grid.nx + i] = std::numeric_limits<double>::quiet_NaN();
  scene.terrain = Terrain(hf, scene.terrain.default_ground());
  SimulationWorkspace ws;
  RockState s;
  s.position_m = {90, 0, 0.3};  // cells from x = 100 m on touch nodata
  s.velocity_m_s = {10, 0, 0};
  EXPECT_EQ(SimulateRock(scene, s, ws).end, EndReason::kLeftDomain);
}

TEST(Simulate, MaxTimeAndNonFiniteStatesAreEndingsNotCrashes) {
  Scene scene = FlatScene();
  scene.options.max_time_s = 0.5;
  SimulationWorkspace ws;
  RockState s;
  s.position_m = {50, 0, 1000};
  RockResult r = SimulateRock(scene, s, ws);
  EXPECT_EQ(r.end, EndReason::kMaxTime);
  EXPECT_NEAR(r.travel_time_s, 0.5, 1e-9);

  s.velocity_m_s.x() = std::numeric_limits<double>::quiet_NaN();
  r = SimulateRock(scene, s, ws);
  EXPECT_EQ(r.end, EndReason::kFailed);
  EXPECT_FALSE(r.message.empty());

  // Finite but absurd: 1e300 m/s and rad/s. The first step takes the rock 2e297 m away, out of the
  // 100 m domain: an ending, not a crash and not a rest.
  s.velocity_m_s.x() = 1e300;
  s.angular_velocity_rad_s = {1e300, 1e300, 0};
  r = SimulateRock(scene, s, ws);
  EXPECT_EQ(r.end, EndReason::kLeftDomain) << ToString(r.end);
  EXPECT_EQ(r.steps, 0);
}

TEST(Simulate, RaiseAboveTerrainLiftsOnlyWhatIsBelow) {
  const Scene scene = FlatScene();
  RockState s;
  s.position_m = {50, 0, 0.1};  // half-height 0.25: 0.15 m below ground
  EXPECT_NEAR(RaiseAboveTerrain(scene, s), 0.15, 1e-12);
  EXPECT_NEAR(s.position_m.z(), 0.25, 1e-12);
  EXPECT_EQ(RaiseAboveTerrain(scene, s), 0.0);
}

TEST(Simulate, SameStartGivesBitIdenticalResults) {
  const Scene scene = scenes::Ramp40();
  SimulationWorkspace ws1, ws2;
  const RockState start = scenes::Ramp40Release(scene, 7, 3);
  const RockResult a = SimulateRock(scene, start, ws1);
  SimulateRock(scene, scenes::Ramp40Release(scene, 7, 4), ws2);  // dirty the second workspace
  const RockResult b = SimulateRock(scene, start, ws2);
  EXPECT_EQ(a.steps, b.steps);
  EXPECT_EQ(a.final_state.position_m, b.final_state.position_m);
  EXPECT_EQ(a.max_kinetic_energy_j, b.max_kinetic_energy_j);
}

TEST(Simulate, CentreOfMassReadingIsBitIdenticalToWave1) {
  // The centre-of-mass reading of the viscous term must reproduce the results from before the
  // option existed bit for bit. Golden values recorded at d7e2d6e (g++ 12.2, Release, x86-64) for
  // Ramp40 rocks 0 (rolls on an edge, 41.6 m/s then) and 1 (tumbles, 6.4 m/s) of seed 1, and
  // recorded again when the free rotation's Newton iteration was written out per component (the
  // same root to 1e-15 relative, so each trajectory diverges from its old self; the ensembles'
  // statistics agree, bench/README.md "Free rotation written out"), and again when the slip
  // Newton stopped one iteration earlier (the same percussions to 1e-11 relative; bench/README.md,
  // "The slip Newton's stopping rule"): a regression check of the scheme's arithmetic, not
  // physics. Tolerance: exact. Recorded with the contact solve's tolerance of then, 1e-7 m/s,
  // which the test sets (the default is 1e-3 m/s since).
  // Another compiler, flags or architecture rounds differently, and a tumbling rock's path
  // amplifies the last bit: the values hold for the project's toolchain (g++ 12 on x86-64, as
  // scripts/setup.sh installs it on Debian 12) and the test is skipped elsewhere, saying why.
#if !(defined(__GNUC__) && !defined(__clang__) && __GNUC__ == 12 && defined(__x86_64__))
  GTEST_SKIP() << "golden values of g++ 12 on x86-64; this build's compiler rounds differently";
#endif
  struct Golden {
    int rock;
    long steps;
    double x, y, z, max_speed, max_kinetic_energy, max_angular_speed;
  };
  const Golden golden[] = {
      {0, 9692, 0x1.5d6fc47ad624p+8, -0x1.059b48a20bf2p+4, 0x1.c0a5930265249p+0,
       0x1.55e2445f4f38p+5, 0x1.9f631662a4e03p+19, 0x1.c2e517f165d09p+5},
      {1, 48339, 0x1.910eeb866ea5fp+7, 0x1.5d7fe4b08a3fcp+1, 0x1.e11b565a10586p-3,
       0x1.99ff7058fd1d4p+2, 0x1.06fc6af8ddd7ep+14, 0x1.e8c2d66aceb2cp+2}};
  Scene scene = scenes::Ramp40();
  scene.options.viscous = ViscousReading::kCentreOfMass;
  scene.options.tolerance_m_s = 1e-7;
  scene.options.impact_substeps = 1;  // the whole steps of then
  scene.options.contact_solve = ContactSolveMethod::kGaussSeidel;  // the sweeps alone of then
  SimulationWorkspace ws;
  for (const Golden& g : golden) {
    const RockResult r = SimulateRock(scene, scenes::Ramp40Release(scene, 1, g.rock), ws);
    EXPECT_EQ(r.steps, g.steps) << "rock " << g.rock;
    EXPECT_EQ(r.final_state.position_m.x(), g.x) << "rock " << g.rock;
    EXPECT_EQ(r.final_state.position_m.y(), g.y) << "rock " << g.rock;
    EXPECT_EQ(r.final_state.position_m.z(), g.z) << "rock " << g.rock;
    EXPECT_EQ(r.max_speed_m_s, g.max_speed) << "rock " << g.rock;
    EXPECT_EQ(r.max_kinetic_energy_j, g.max_kinetic_energy) << "rock " << g.rock;
    EXPECT_EQ(r.max_angular_speed_rad_s, g.max_angular_speed) << "rock " << g.rock;
  }
}

TEST(Simulate, BlockOnStallConvergesTheRampStepsWhereGaussSeidelStalls) {
  // The benchmark ramp's first 8 rocks of seed 1 under Gauss-Seidel alone and with the block on
  // stall (ContactSolveMethod::kBlockOnStall), default tolerance (1e-3 m/s) and max_iterations
  // (200): Gauss-Seidel leaves steps unconverged (the premise), the block on stall at most a
  // tenth as many, and it sweeps less in all. Measured: 45 unconverged steps and 61 714 sweeps
  // against 1 and 61 061.
  long unconverged[2] = {0, 0}, sweeps[2] = {0, 0};
  const ContactSolveMethod methods[2] = {ContactSolveMethod::kGaussSeidel,
                                         ContactSolveMethod::kBlockOnStall};
  for (int m = 0; m < 2; ++m) {
    Scene scene = scenes::Ramp40();
    scene.options.contact_solve = methods[m];
    SimulationWorkspace ws;
    for (int rock = 0; rock < 8; ++rock) {
      const RockResult r = SimulateRock(scene, scenes::Ramp40Release(scene, 1, rock), ws);
      unconverged[m] += r.unconverged_steps;
      sweeps[m] += r.solver_iterations;
    }
  }
  std::printf("unconverged steps %ld / %ld, sweeps %ld / %ld (gauss_seidel / block_on_stall)\n",
              unconverged[0], unconverged[1], sweeps[0], sweeps[1]);
  EXPECT_GT(unconverged[0], 0);
  EXPECT_LE(unconverged[1], unconverged[0] / 10);
  EXPECT_LT(sweeps[1], sweeps[0]);
}

TEST(Random, StreamsDependOnSeedAndRockOnlyAndOrientationsAreUniform) {
  RockRandom a(5, 9), b(5, 9), c(5, 10);
  EXPECT_EQ(a.Uniform(), b.Uniform());
  EXPECT_NE(RockRandom(5, 9).Uniform(), c.Uniform());
  // Uniform rotations: the rotated z axis is uniform on the sphere, so its mean is 0 and the
  // mean of z^2 is 1/3 (standard error ~ 0.3/sqrt(n); tolerance 4 standard errors).
  const int n = 20000;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  double zz = 0;
  for (int k = 0; k < n; ++k) {
    const Eigen::Vector3d z = RockRandom(1, k).Orientation() * Eigen::Vector3d::UnitZ();
    mean += z / n;
    zz += z.z() * z.z() / n;
  }
  EXPECT_LT(mean.norm(), 4 * 0.58 / std::sqrt(n));
  EXPECT_NEAR(zz, 1.0 / 3, 4 * 0.3 / std::sqrt(n));
}

}  // namespace
}  // namespace talus

namespace talus {
namespace {

// No step may raise the mechanical energy by more than the scheme's derived plastic bound
// (testing::StepEnergyBound: m g^2 dt^2 / 8 plus the work of a solve stopped at its tolerance),
// to round-off; the run must end without a non-finite state, must meet the ground and must end
// with less mechanical energy than it started with (its landing is a plastic impact).
void ExpectStableAndDissipative(const Scene& scene, RockState s, const char* what) {
  const double m = scene.rock.mass_kg, g = scene.options.gravity_m_s2;
  StepWorkspace ws;
  ws.Reset(scene.rock.vertices_m.size());
  const double e0 = KineticEnergy(scene.rock, s) + m * g * s.position_m.z();
  double e = e0, worst_excess = -1, running_min = e0, worst_rise = 0;
  long contact_steps = 0;
  for (int k = 0; k < 20000; ++k) {
    const StepReport r = Step(scene, s, ws);
    if (r.outside_domain) break;
    ASSERT_TRUE(s.position_m.allFinite() && s.velocity_m_s.allFinite()) << what;
    contact_steps += r.contacts > 0;
    const double next = KineticEnergy(scene.rock, s) + m * g * s.position_m.z();
    worst_excess =
        std::max(worst_excess, (next - e - testing::StepEnergyBound(scene, ws, r)) / std::abs(e0));
    e = next;
    running_min = std::min(running_min, e);
    worst_rise = std::max(worst_rise, (e - running_min) / std::abs(e0));
  }
  std::printf(
      "%s, %s: %ld contact steps, worst energy rise %.2e, worst step beyond its bound %.2e\n", what,
      ToString(scene.options.viscous), contact_steps, worst_rise, worst_excess);
  EXPECT_GT(contact_steps, 0) << what << ", " << ToString(scene.options.viscous);
  EXPECT_LT(e, e0) << what << ", " << ToString(scene.options.viscous);
  EXPECT_LT(worst_excess, testing::kEnergyRoundOff)
      << what << ", " << ToString(scene.options.viscous);
}

void RunExtremes(ViscousReading reading) {
  const GroundParams hard{0.55, 2.0, 185, 3.0, 0.4}, snow{0.10, 0.35, 150, 2.0, 0.7};
  {  // a 5 cm pebble (0.3 kg) down 60 degrees at dt = 2 ms
    Scene scene = scenes::Incline(60, MakeRockShape(MakeBox(0.05, 0.04, 0.03), 2700), hard, 200, 2);
    scene.options.viscous = reading;
    RockState s;
    s.orientation = RockRandom(3, 0).Orientation();
    s.position_m = {20, 0, 180 * std::tan(60 * M_PI / 180) + 0.1};
    ExpectStableAndDissipative(scene, s, "pebble");
  }
  {  // a 94 t platy block (34 m^3, like Brienz 2014) thrown at 50 m/s onto 35 degrees
    Scene scene = scenes::Incline(35, MakeRockShape(MakeBox(6, 4.5, 1.26), 2700), hard, 400, 5);
    scene.options.viscous = reading;
    RockState s;
    s.orientation = RockRandom(3, 1).Orientation();
    s.position_m = {50, 0, 350 * std::tan(35 * M_PI / 180) + 5};
    s.velocity_m_s = {45, 5, -20};
    ExpectStableAndDissipative(scene, s, "Brienz-size block");
  }
  {  // a block spinning at 60 rad/s landing on snow at 30 degrees
    Scene scene = scenes::Incline(30, MakeRockShape(MakeBox(1, 0.6, 0.3), 2700), snow, 200, 2);
    scene.options.viscous = reading;
    RockState s;
    s.orientation = RockRandom(3, 2).Orientation();
    s.position_m = {20, 0, 180 * std::tan(30 * M_PI / 180) + 1};
    s.angular_velocity_rad_s = {60, -20, 5};
    ExpectStableAndDissipative(scene, s, "spinning on snow");
  }
  {  // an 85 degree face (near-vertical cliff), EOTA221
    Scene scene = scenes::Incline(85, scenes::Eota221(), hard, 60, 1);
    scene.options.viscous = reading;
    RockState s;
    s.orientation = RockRandom(3, 3).Orientation();
    s.position_m = {5, 0, 55 * std::tan(85 * M_PI / 180) + 1};
    s.velocity_m_s = {-2, 0, 0};  // pushed into the face
    ExpectStableAndDissipative(scene, s, "cliff");
  }
}

TEST(Extremes, SmallFastHugeSpinningAndSteepStayStableAndDissipative) {
  // Under both readings of the viscous term.
  for (ViscousReading reading : {ViscousReading::kCentreOfMass, ViscousReading::kContactFriction})
    RunExtremes(reading);
}

}  // namespace
}  // namespace talus
