// Barriers acting on a rock during its run (solver/barriers.hpp, docs/model.md "Barriers"),
// against closed forms: a cube sliding on flat ground with constant Coulomb friction mu and no
// viscous term decelerates at mu g, so its kinetic energy after a distance d is
// E(d) = E0 - mu m g d and it stops after E0 / (mu m g) (Coulomb's law; DESIGN.md section 2 with
// mu_min = mu_max). A barrier at distance d that stops it leaves it at d; one it breaks through
// takes its capacity C, so it stops C / (mu m g) short of where it would have stopped without the
// barrier. A cube in free flight over a barrier lower than it passes unchanged, bit for bit.

#include "solver/barriers.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "scenes/scenes.hpp"
#include "solver/random.hpp"
#include "solver/shapes.hpp"
#include "solver/simulate.hpp"

namespace talus {
namespace {

constexpr double kG = 9.81, kMu = 0.5, kSide_m = 1, kDensity = 2700;
constexpr double kStartX_m = 20, kV0_m_s = 10, kBarrierX_m = 25;

// Flat ground of constant friction mu (mu_min = mu_max), no viscous term, and a 1 m cube; the
// contact solve at 1e-9 m/s so that the friction's deceleration is mu g to round-off.
Scene SlidingScene() {
  Scene scene = scenes::Incline(0, MakeRockShape(MakeBox(kSide_m, kSide_m, kSide_m), kDensity),
                                GroundParams{kMu, kMu, 150, 2, 0});
  scene.options.tolerance_m_s = 1e-9;
  scene.options.max_iterations = 1000;
  scene.options.max_time_s = 10;
  return scene;
}

// A barrier across the path at x (from y = -20 to 20).
Barrier Across(double x, double height_m, double capacity_J) {
  Barrier b;
  b.name = "net";
  b.type = BarrierType::kFlexibleNet;
  b.vertices_m = {{x, -20}, {x, 20}};
  b.height_m = height_m;
  b.capacity_J = capacity_J;
  return b;
}

// The cube resting on the ground at x = 20 and sliding along +x at v0.
RockState SlidingStart(const Scene& scene) {
  RockState s;
  s.position_m = {kStartX_m, 0, 0.5 * kSide_m};
  s.velocity_m_s = {kV0_m_s, 0, 0};
  RaiseAboveTerrain(scene, s);
  return s;
}

// Kinetic energy of the cube after sliding d: E0 - mu m g d (Coulomb friction, constant).
double SlidingEnergy(double mass_kg, double d_m) {
  return 0.5 * mass_kg * kV0_m_s * kV0_m_s - kMu * mass_kg * kG * d_m;
}

// Records the kinetic energy after every step.
class EnergyLog : public StepObserver {
 public:
  explicit EnergyLog(const RockShape& rock) : rock_(rock) {}
  void OnStep(const RockState& state, const StepReport&, const TerrainSample&) override {
    energy_J.push_back(KineticEnergy(rock_, state));
    x_m.push_back(state.position_m.x());
  }
  std::vector<double> energy_J, x_m;

 private:
  const RockShape& rock_;
};

TEST(Barriers, SlidingCubeBelowCapacityStopsAtTheBarrier) {
  Scene scene = SlidingScene();
  const double m = scene.rock.mass_kg;
  const double e_at_barrier = SlidingEnergy(m, kBarrierX_m - kStartX_m);  // 68.8 kJ
  scene.barriers = {Across(kBarrierX_m, 3, e_at_barrier + 1000)};
  SimulationWorkspace ws;
  const RockResult r = SimulateRock(scene, SlidingStart(scene), ws);
  ASSERT_EQ(r.end, EndReason::kBarrier);
  ASSERT_EQ(r.barrier_events.size(), 1u);
  const BarrierEvent& e = r.barrier_events[0];
  EXPECT_EQ(e.outcome, BarrierOutcome::kStopped);
  EXPECT_EQ(e.barrier, 0);
  // At rest on the barrier's line, where its centre of mass crossed it.
  EXPECT_NEAR(r.final_state.position_m.x(), kBarrierX_m, 1e-9);
  EXPECT_EQ(r.final_state.velocity_m_s.norm(), 0);
  EXPECT_EQ(r.final_state.angular_velocity_rad_s.norm(), 0);
  EXPECT_NEAR(r.runout_m, kBarrierX_m - kStartX_m, 1e-9);
  EXPECT_EQ(e.energy_after_J, 0);
  // The impact energy is the closed form's: the midpoint scheme integrates the constant
  // deceleration exactly and the velocity is linear within a step; the contact solve leaves
  // 1e-9 m/s and the cube's pitching under friction a little rotation: 1e-6 relative.
  EXPECT_NEAR(e.energy_J(), e_at_barrier, 1e-6 * e_at_barrier);
  // The cube slides on its face: it touches, so its passing height is 0.
  EXPECT_NEAR(e.passing_height_m, 0, 1e-6);
  EXPECT_NEAR(r.travel_time_s, (kV0_m_s - std::sqrt(2 * e_at_barrier / m)) / (kMu * kG), 1e-6);
}

TEST(Barriers, SlidingCubeAboveCapacityBreaksThroughWithItsEnergyLessTheCapacity) {
  Scene scene = SlidingScene();
  const double m = scene.rock.mass_kg;
  constexpr double kCapacity_J = 30000;
  const double e_at_barrier = SlidingEnergy(m, kBarrierX_m - kStartX_m);  // 68.8 kJ
  SimulationWorkspace ws;
  const RockResult free = SimulateRock(scene, SlidingStart(scene), ws);
  scene.barriers = {Across(kBarrierX_m, 3, kCapacity_J)};
  EnergyLog log(scene.rock);
  const RockResult r = SimulateRock(scene, SlidingStart(scene), ws, &log);
  ASSERT_EQ(r.end, EndReason::kRest);
  ASSERT_EQ(r.barrier_events.size(), 1u);
  const BarrierEvent& e = r.barrier_events[0];
  EXPECT_EQ(e.outcome, BarrierOutcome::kBrokeThrough);
  EXPECT_NEAR(e.energy_J(), e_at_barrier, 1e-6 * e_at_barrier);
  // E_after = E_before - C, to round-off.
  EXPECT_NEAR(e.energy_after_J, e.energy_J() - kCapacity_J, 1e-9 * e.energy_J());
  // The end of the step that crossed: E_before - C less the friction's work mu m g (x - x_b) from
  // the crossing to the step's end (the barrier's energy is taken from the step's end state).
  std::size_t k = 0;
  while (log.x_m[k] < kBarrierX_m) ++k;
  const double friction_J = kMu * m * kG * (log.x_m[k] - kBarrierX_m);
  EXPECT_NEAR(log.energy_J[k], e.energy_J() - kCapacity_J - friction_J, 1e-6 * e_at_barrier);
  // Closed form: it stops C / (mu m g) = 2.27 m short of the run without the barrier. Both runs'
  // rest positions carry the scheme's stopping error (the last step's v dt / 2 at most, with
  // v < mu g dt in it: 1e-5 m), each run's own: 1e-4 m.
  const double shorter_m = kCapacity_J / (kMu * m * kG);
  EXPECT_NEAR(free.runout_m - r.runout_m, shorter_m, 1e-4);
  EXPECT_NEAR(free.runout_m, 0.5 * kV0_m_s * kV0_m_s / (kMu * kG), 1e-3);
}

TEST(Barriers, CubeFlyingAboveTheBarrierPassesBitForBitUnchanged) {
  // Thrown horizontally at 10 m/s from 5 m: at x = 25 (t = 0.5 s) its centre of mass is at
  // 5 - g t^2 / 2 = 3.774 m and its lowest vertex 0.5 m below, 3.274 m above the ground, higher
  // than the 2 m barrier. The parabola is exact at the steps' ends; within a step the chord
  // departs from it by at most g dt^2 / 8 = 4.9e-6 m.
  Scene scene = SlidingScene();
  RockState start;
  start.position_m = {kStartX_m, 0, 5};
  start.velocity_m_s = {kV0_m_s, 0, 0};
  start.angular_velocity_rad_s = {0, 0, 0};
  SimulationWorkspace ws;
  const RockResult free = SimulateRock(scene, start, ws);
  scene.barriers = {Across(kBarrierX_m, 2, 1000)};
  const RockResult r = SimulateRock(scene, start, ws);
  ASSERT_EQ(r.barrier_events.size(), 1u);
  const BarrierEvent& e = r.barrier_events[0];
  EXPECT_EQ(e.outcome, BarrierOutcome::kOvertopped);
  EXPECT_NEAR(e.passing_height_m, 5 - 0.5 * kG * 0.25 - 0.5, 1e-5);
  EXPECT_NEAR(e.t_s, 0.5, 1e-12);
  EXPECT_EQ(e.energy_after_J, e.energy_J());
  EXPECT_EQ(r.end, free.end);
  EXPECT_EQ(r.steps, free.steps);
  EXPECT_EQ(r.final_state.position_m, free.final_state.position_m);
  EXPECT_EQ(r.final_state.velocity_m_s, free.final_state.velocity_m_s);
  EXPECT_EQ(r.final_state.orientation.coeffs(), free.final_state.orientation.coeffs());
  EXPECT_EQ(r.max_kinetic_energy_j, free.max_kinetic_energy_j);
  // The same throw into a 4 m barrier hits it (3.274 m < 4 m): in flight the kinetic energy at
  // the crossing is 1/2 m (v0^2 + (g t)^2) exactly (no contact), and 1 kJ stops nothing of it.
  scene.barriers = {Across(kBarrierX_m, 4, 1000)};
  const RockResult hit = SimulateRock(scene, start, ws);
  ASSERT_EQ(hit.barrier_events.size(), 1u);
  EXPECT_EQ(hit.barrier_events[0].outcome, BarrierOutcome::kBrokeThrough);
  const double m = scene.rock.mass_kg;
  const double e_flight = 0.5 * m * (kV0_m_s * kV0_m_s + kG * kG * 0.25);
  EXPECT_NEAR(hit.barrier_events[0].energy_J(), e_flight, 1e-9 * e_flight);
}

// Contacts never add energy; neither does a barrier. Random tumbling rocks down a 40 deg incline
// through a 0.3 m net of 25 kJ (of the 12, measured: 2 overtop it, 6 are stopped, 4 break through):
// the runs with and without it are the same step for step up to the crossing (the same bits), and
// in the step that crosses, and in every event, the rock with the barrier has no more kinetic
// energy than without it.
TEST(Barriers, NoBarrierAddsEnergy) {
  Scene scene = scenes::Incline(40, MakeRockShape(MakeBox(0.8, 0.6, 0.4), kDensity),
                                GroundParams{0.35, 2.0, 150, 2, 0.6});
  scene.options.max_time_s = 8;
  int broke = 0, stopped = 0, overtopped = 0;
  for (long rock = 0; rock < 12; ++rock) {
    RockState start;
    start.position_m = {20, 0, 0};
    RockRandom random(7, static_cast<std::uint64_t>(rock));
    start.orientation = random.Orientation();
    start.velocity_m_s = {8, 0, -2};
    RaiseAboveTerrain(scene, start);
    start.position_m.z() += 1;
    scene.barriers.clear();
    SimulationWorkspace ws;
    EnergyLog without_log(scene.rock);
    SimulateRock(scene, start, ws, &without_log);
    scene.barriers = {Across(40, 0.3, 25000)};
    EnergyLog with_log(scene.rock);
    const RockResult r = SimulateRock(scene, start, ws, &with_log);
    std::size_t k = 0;
    while (k < with_log.energy_J.size() && k < without_log.energy_J.size() &&
           with_log.energy_J[k] == without_log.energy_J[k])
      ++k;
    if (k < with_log.energy_J.size() && k < without_log.energy_J.size()) {
      EXPECT_LE(with_log.energy_J[k], without_log.energy_J[k]) << "rock " << rock;
    }
    for (const BarrierEvent& e : r.barrier_events) {
      EXPECT_LE(e.energy_after_J, e.energy_J()) << "rock " << rock;
      EXPECT_GE(e.energy_after_J, 0);
      broke += e.outcome == BarrierOutcome::kBrokeThrough;
      stopped += e.outcome == BarrierOutcome::kStopped;
      overtopped += e.outcome == BarrierOutcome::kOvertopped;
    }
  }
  std::printf("broke through %d, stopped %d, overtopped %d\n", broke, stopped, overtopped);
  EXPECT_GT(broke, 0);
  EXPECT_GT(stopped, 0);
  EXPECT_GT(overtopped, 0);
}

TEST(Barriers, InvalidBarriersAreNamed) {
  std::string why;
  Barrier b = Across(10, 2, 1000);
  EXPECT_TRUE(b.IsValid(&why)) << why;
  b.capacity_J = 0;
  EXPECT_FALSE(b.IsValid(&why));
  EXPECT_NE(why.find("capacity_J = 0"), std::string::npos) << why;
  b = Across(10, -1, 1000);
  EXPECT_FALSE(b.IsValid(&why));
  EXPECT_NE(why.find("height_m = -1"), std::string::npos) << why;
  b = Across(10, 2, 1000);
  b.vertices_m.pop_back();
  EXPECT_FALSE(b.IsValid(&why));
  EXPECT_NE(why.find("at least 2 vertices"), std::string::npos) << why;
  BarrierType type;
  EXPECT_TRUE(ParseBarrierType("rigid_wall", &type));
  EXPECT_EQ(type, BarrierType::kRigidWall);
  EXPECT_FALSE(ParseBarrierType("fence", &type));
  Scene scene = SlidingScene();
  scene.barriers = {b};
  EXPECT_FALSE(scene.IsValid(&why));
  EXPECT_NE(why.find("barrier 'net'"), std::string::npos) << why;
}

}  // namespace
}  // namespace talus
