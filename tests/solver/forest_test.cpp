// Trees acting on a rock (solver/forest.hpp, docs/model.md "Forest"), against closed forms.
// A rigid body whose point a (from the centre of mass) gets a percussion P changes its velocity
// by P / m and its angular velocity by Theta^-1 (a x P) (Newton-Euler for impulses). For a cube
// of side s hitting a stem head-on with the centre of a face, a = (s/2) n: the normal percussion
// has no lever, so the plastic impact takes the normal velocity v_N entirely (P_N = m v_N).
// The tangential percussion P_T at a changes the point's tangential velocity by
// P_T (1/m + (s/2)^2 / Theta), Theta = m s^2 / 6: it sticks when that stops the point with
// |P_T| <= mu P_N, and else slides with |P_T| = mu P_N, which takes mu v_N from the centre of
// mass's tangential velocity (Coulomb's law during a plastic impact). A stem that breaks leaves
// the rock E - E_max with its directions (the model's rule, as for barriers). On flat ground with
// constant Coulomb friction mu a sliding cube's energy after a distance d is E0 - mu m g d.

#include "solver/forest.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "scenes/scenes.hpp"
#include "solver/random.hpp"
#include "solver/shapes.hpp"
#include "solver/simulate.hpp"
#include "solver/step.hpp"

namespace talus {
namespace {

constexpr double kG = 9.81, kMu = 0.5, kSide_m = 1, kDensity = 2700;

RockShape Cube() { return MakeRockShape(MakeBox(kSide_m, kSide_m, kSide_m), kDensity); }

// The cube's principal frame is the box's (its vertices at +-s/2 on every axis): the closed forms
// below assume the faces are normal to x, y and z at identity orientation.
bool AxisAligned(const RockShape& rock) {
  for (const Eigen::Vector3d& v : rock.vertices_m)
    if ((v.cwiseAbs() - Eigen::Vector3d::Constant(0.5 * kSide_m)).norm() > 1e-9) return false;
  return true;
}

// One stem of diameter dbh at (x, y) on ground at height 0.
Forest OneStem(double x, double y, double dbh_m, double friction = kMu) {
  ForestModel model;
  model.friction = friction;
  return Forest({Stem{{x, y}, dbh_m, 0}}, model);
}

// The cube at the origin (centre of mass 0.5 m up) moving with v; a stem of 30 cm whose surface
// is 1 cm inside the cube's face x = 0.5.
struct HeadOn {
  RockShape rock = Cube();
  Forest forest = OneStem(0.5 * kSide_m + 0.15 - 0.01, 0, 0.3);
  RockState State(const Eigen::Vector3d& v) const {
    RockState s;
    s.position_m = {0, 0, 0.5 * kSide_m};
    s.velocity_m_s = v;
    return s;
  }
};

TEST(Forest, DefaultsAreValidAndTheBreakingEnergyIsTheStatedPowerLaw) {
  const ForestModel model;
  std::string why;
  EXPECT_TRUE(model.IsValid(&why)) << why;
  // E_max = 38.7 DBH[cm]^2.31 J: 30 cm -> 38.7 * 30^2.31 = 99.96 kJ.
  EXPECT_NEAR(model.BreakingEnergy_J(0.30), 38.7 * std::pow(30.0, 2.31), 1e-9);
  EXPECT_NEAR(model.BreakingEnergy_J(0.30), 99960, 10);
  ForestModel bad;
  bad.stem_height_m = 0;
  EXPECT_FALSE(bad.IsValid(&why));
  EXPECT_NE(why.find("stem_height_m = 0"), std::string::npos) << why;
  bad = ForestModel{};
  bad.friction = -1;
  EXPECT_FALSE(bad.IsValid(&why));
  EXPECT_NE(why.find("friction = -1"), std::string::npos) << why;
  const Forest negative({Stem{{0, 0}, -0.2, 0}}, ForestModel{});
  EXPECT_FALSE(negative.IsValid(&why));
  EXPECT_NE(why.find("dbh"), std::string::npos) << why;
}

TEST(Forest, TheGridFindsEveryStemWithinReach) {
  // Against a brute-force search over 2000 random stems on 200 m x 100 m.
  std::vector<Stem> stems;
  RockRandom random(3, 0);
  for (int k = 0; k < 2000; ++k)
    stems.push_back(Stem{{200 * random.Uniform() - 50, 100 * random.Uniform()}, 0.3, 0});
  const Forest forest(stems, ForestModel{});
  for (int q = 0; q < 200; ++q) {
    const Eigen::Vector2d c(260 * random.Uniform() - 80, 140 * random.Uniform() - 20);
    const double reach = 4 * random.Uniform();
    std::vector<int> found;
    forest.ForEachNear(c, reach, [&](int k) { found.push_back(k); });
    for (std::size_t k = 0; k < stems.size(); ++k) {
      if ((stems[k].position_m - c).norm() > reach) continue;
      EXPECT_NE(std::find(found.begin(), found.end(), static_cast<int>(k)), found.end())
          << "stem " << k << " missed from query " << q;
    }
    std::vector<int> sorted = found;
    std::sort(sorted.begin(), sorted.end());
    EXPECT_EQ(std::adjacent_find(sorted.begin(), sorted.end()), sorted.end()) << "a stem twice";
  }
}

TEST(Forest, HeadOnBelowTheBreakingEnergyTheStemTakesTheNormalVelocity) {
  const HeadOn h;
  ASSERT_TRUE(AxisAligned(h.rock));
  RockState s = h.State({5, 0, 0});  // 33.75 kJ < E_max(30 cm) = 99.96 kJ
  const double e0 = KineticEnergy(h.rock, s);
  std::vector<StemHit> hits;
  EXPECT_TRUE(MeetStems(h.forest, h.rock, &s, &hits));
  // Plastic: nothing left along the normal, and no lever, so no spin: 1e-12 m/s (round-off of
  // the 3x3 solve).
  EXPECT_NEAR(s.velocity_m_s.norm(), 0, 1e-12);
  EXPECT_NEAR(s.angular_velocity_rad_s.norm(), 0, 1e-12);
  ASSERT_EQ(hits.size(), 1u);
  EXPECT_EQ(hits[0].impacts, 1);
  EXPECT_FALSE(hits[0].broken);
  EXPECT_NEAR(hits[0].absorbed_J, e0, 1e-9 * e0);
  EXPECT_EQ(hits[0].energy_J, e0);
  // Still overlapping, at rest: the same episode, nothing more to take.
  EXPECT_FALSE(MeetStems(h.forest, h.rock, &s, &hits));
  EXPECT_EQ(hits[0].impacts, 1);
}

TEST(Forest, HeadOnAboveTheBreakingEnergyTheStemBreaksAndTakesItsEnergy) {
  const HeadOn h;
  RockState s = h.State({10, 0, 0});  // 135 kJ > 99.96 kJ
  const double e0 = KineticEnergy(h.rock, s);
  const double e_max = h.forest.capacity_J(0);
  std::vector<StemHit> hits;
  EXPECT_TRUE(MeetStems(h.forest, h.rock, &s, &hits));
  ASSERT_EQ(hits.size(), 1u);
  EXPECT_TRUE(hits[0].broken);
  EXPECT_EQ(hits[0].absorbed_J, e_max);
  // E - E_max, to round-off, along +x.
  EXPECT_NEAR(KineticEnergy(h.rock, s), e0 - e_max, 1e-9 * e0);
  EXPECT_NEAR(s.velocity_m_s.x(), std::sqrt(2 * (e0 - e_max) / h.rock.mass_kg), 1e-9);
  EXPECT_EQ(s.velocity_m_s.y(), 0);
  // Gone for this rock: the next overlap does nothing.
  const RockState after = s;
  EXPECT_FALSE(MeetStems(h.forest, h.rock, &s, &hits));
  EXPECT_EQ(s.velocity_m_s, after.velocity_m_s);
  // Not for another rock.
  std::vector<StemHit> other;
  RockState t = h.State({1, 0, 0});
  EXPECT_TRUE(MeetStems(h.forest, h.rock, &t, &other));
}

TEST(Forest, ObliqueImpactSticksOrSlidesByCoulomb) {
  const HeadOn h;
  const double m = h.rock.mass_kg, theta = m * kSide_m * kSide_m / 6, arm = 0.5 * kSide_m;
  const double v_n = 4, v_t = 3;
  for (const double mu : {0.5, 0.2}) {
    const Forest forest = OneStem(0.5 * kSide_m + 0.15 - 0.01, 0, 0.3, mu);
    RockState s = h.State({v_n, v_t, 0});
    std::vector<StemHit> hits;
    ASSERT_TRUE(MeetStems(forest, h.rock, &s, &hits));
    // Sticking percussion: the point's tangential velocity to 0 through 1/m + arm^2/Theta.
    const double stick = v_t / (1 / m + arm * arm / theta);
    const double p_t = std::min(stick, mu * m * v_n);  // mu = 0.5 sticks, 0.2 slides
    EXPECT_NEAR(s.velocity_m_s.x(), 0, 1e-12);
    // 1e-9: the sliding case's local iteration stops at 1e-14 relative change.
    EXPECT_NEAR(s.velocity_m_s.y(), v_t - p_t / m, 1e-9) << "mu " << mu;
    EXPECT_NEAR(s.velocity_m_s.z(), 0, 1e-12);
    // The percussion -p_t y at arm x turns the cube about -z: arm p_t / Theta.
    const Eigen::Vector3d w = s.orientation * s.angular_velocity_rad_s;
    EXPECT_NEAR(w.z(), -arm * p_t / theta, 1e-9) << "mu " << mu;
    if (mu == 0.5) {
      EXPECT_NEAR(s.velocity_m_s.y() + w.z() * arm, 0, 1e-9);  // stuck
    }
  }
}

TEST(Forest, NoImpactAddsEnergy) {
  // Random shapes' orientations, velocities, spins, stem sizes and friction coefficients, the
  // EOTA221 block overlapping a stem: the impact never adds kinetic energy (1e-12 relative:
  // round-off).
  const RockShape rock = scenes::Eota221();
  int acted = 0;
  for (int k = 0; k < 2000; ++k) {
    RockRandom random(11, static_cast<std::uint64_t>(k));
    const double dbh = 0.05 + 0.6 * random.Uniform();
    const double angle = 2 * M_PI * random.Uniform();
    const double distance = rock.bounding_radius_m * random.Uniform();
    ForestModel model;
    model.friction = 1.5 * random.Uniform();
    model.energy_coefficient_J = random.Uniform() < 0.5 ? 38.7 : 1e-3;  // hold or break
    const Forest forest({Stem{{distance * std::cos(angle), distance * std::sin(angle)}, dbh, -2}},
                        model);
    RockState s;
    s.orientation = random.Orientation();
    for (int i = 0; i < 3; ++i) {
      s.velocity_m_s[i] = 20 * (random.Uniform() - 0.5);
      s.angular_velocity_rad_s[i] = 10 * (random.Uniform() - 0.5);
    }
    const double e0 = KineticEnergy(rock, s);
    std::vector<StemHit> hits;
    if (MeetStems(forest, rock, &s, &hits)) ++acted;
    EXPECT_LE(KineticEnergy(rock, s), e0 * (1 + 1e-12)) << "case " << k;
    for (const StemHit& h : hits) EXPECT_LE(h.absorbed_J, forest.capacity_J(0) * (1 + 1e-12));
  }
  EXPECT_GT(acted, 500);  // the draws do exercise impacts
}

// The sliding cube of the barrier tests: flat ground of constant friction, 1 m cube at x = 20
// sliding along +x at 10 m/s.
Scene SlidingScene() {
  Scene scene = scenes::Incline(0, Cube(), GroundParams{kMu, kMu, 150, 2, 0});
  scene.options.tolerance_m_s = 1e-9;
  scene.options.max_iterations = 1000;
  scene.options.max_time_s = 10;
  return scene;
}

RockState SlidingStart(const Scene& scene) {
  RockState s;
  s.position_m = {20, 0, 0.5 * kSide_m};
  s.velocity_m_s = {10, 0, 0};
  RaiseAboveTerrain(scene, s);
  return s;
}

TEST(Forest, SlidingCubeIsStoppedByAStemBelowItsBreakingEnergy) {
  Scene scene = SlidingScene();
  const double m = scene.rock.mass_kg;
  constexpr double kDbh = 0.4, kStemX = 25.7;  // E_max(40 cm) = 195 kJ
  scene.forest = OneStem(kStemX, 0, kDbh);
  SimulationWorkspace ws;
  const RockResult r = SimulateRock(scene, SlidingStart(scene), ws);
  ASSERT_EQ(r.end, EndReason::kRest);
  ASSERT_EQ(r.stem_hits.size(), 1u);
  const StemHit& hit = r.stem_hits[0];
  EXPECT_FALSE(hit.broken);
  EXPECT_EQ(hit.impacts, 1);
  // It rests with its face against the stem: the overlap found after a step is at most that
  // step's travel v dt = 0.02 m.
  const double contact_x = kStemX - 0.5 * kDbh - 0.5 * kSide_m;
  EXPECT_NEAR(r.final_state.position_m.x(), contact_x, 0.02);
  EXPECT_LE(r.final_state.position_m.x(), contact_x + 1e-12 + 0.02);
  // Energy at impact: E0 - mu m g d (closed form) with d to the contact, within the friction
  // work over the same 0.02 m of detection lag (mu m g 0.02 = 265 J); the stem took all of it.
  const double expected = 0.5 * m * 100 - kMu * m * kG * (contact_x - 20);
  EXPECT_NEAR(hit.energy_J, expected, kMu * m * kG * 0.02);
  EXPECT_NEAR(hit.absorbed_J, hit.energy_J, 1e-6 * hit.energy_J);
}

TEST(Forest, SlidingCubeBreaksAStemAboveItsBreakingEnergyAndStopsShorter) {
  Scene scene = SlidingScene();
  const double m = scene.rock.mass_kg;
  constexpr double kDbh = 0.2;  // E_max(20 cm) = 38.7 * 20^2.31 = 39.0 kJ < 62 kJ at the stem
  SimulationWorkspace ws;
  const RockResult free = SimulateRock(scene, SlidingStart(scene), ws);
  scene.forest = OneStem(26, 0, kDbh);
  const RockResult r = SimulateRock(scene, SlidingStart(scene), ws);
  ASSERT_EQ(r.end, EndReason::kRest);
  ASSERT_EQ(r.stem_hits.size(), 1u);
  EXPECT_TRUE(r.stem_hits[0].broken);
  const double e_max = scene.forest.capacity_J(0);
  EXPECT_EQ(r.stem_hits[0].absorbed_J, e_max);
  // Closed form: losing E_max on the way it stops E_max / (mu m g) = 2.95 m short of the free
  // run. Each run's rest carries the scheme's stopping error (1e-5 m, barrier tests) and the
  // cube's pitching under friction: 1e-3 m.
  EXPECT_NEAR(free.runout_m - r.runout_m, e_max / (kMu * m * kG), 1e-3);
}

// One stem of DBH 20 cm at x = 26 of the species `law` (the only species of the model).
Forest OneStemOfSpecies(const TreeSpecies& law) {
  ForestModel model;
  model.friction = kMu;
  model.species = {law};
  return Forest({Stem{{26, 0}, 0.2, 0, 0}}, model);
}

TEST(Forest, ASpeciesFactorScalesTheBreakingEnergyAndTheSlidingCubesShortfall) {
  // The test above with the stem of a species whose law is k times the forest's: E_max = k E_max
  // (exactly: the factor multiplies the forest's law as computed), and the cube, losing k E_max,
  // stops k E_max / (mu m g) short of the free run. Both k keep k E_max = 19.5 and 58.5 kJ below
  // the 62 kJ at the stem, so it breaks. Tolerance 1e-3 m, as above: each run's rest carries the
  // scheme's stopping error and the cube's pitching, neither of which depends on k.
  Scene scene = SlidingScene();
  const double m = scene.rock.mass_kg;
  const double e_max = ForestModel{}.BreakingEnergy_J(0.2);
  SimulationWorkspace ws;
  const RockResult free = SimulateRock(scene, SlidingStart(scene), ws);
  for (const double k : {0.5, 1.5}) {
    SCOPED_TRACE(k);
    TreeSpecies species;
    species.name = "scaled";
    species.energy_factor = k;
    scene.forest = OneStemOfSpecies(species);
    std::string why;
    ASSERT_TRUE(scene.forest.IsValid(&why)) << why;
    EXPECT_EQ(scene.forest.capacity_J(0), k * e_max);
    const RockResult r = SimulateRock(scene, SlidingStart(scene), ws);
    ASSERT_EQ(r.end, EndReason::kRest);
    ASSERT_EQ(r.stem_hits.size(), 1u);
    EXPECT_TRUE(r.stem_hits[0].broken);
    EXPECT_EQ(r.stem_hits[0].absorbed_J, k * e_max);
    EXPECT_NEAR(free.runout_m - r.runout_m, k * e_max / (kMu * m * kG), 1e-3);
  }
}

TEST(Forest, ASpeciesOfFactorOneRunsBitForBitAsNoSpecies) {
  Scene scene = SlidingScene();
  SimulationWorkspace ws;
  scene.forest = OneStem(26, 0, 0.2);
  const RockResult plain = SimulateRock(scene, SlidingStart(scene), ws);
  TreeSpecies species;
  species.name = "spruce";
  scene.forest = OneStemOfSpecies(species);
  const RockResult r = SimulateRock(scene, SlidingStart(scene), ws);
  EXPECT_EQ(r.final_state.position_m, plain.final_state.position_m);
  EXPECT_EQ(r.final_state.velocity_m_s, plain.final_state.velocity_m_s);
  EXPECT_EQ(r.steps, plain.steps);
  ASSERT_EQ(r.stem_hits.size(), 1u);
  EXPECT_EQ(r.stem_hits[0].absorbed_J, plain.stem_hits[0].absorbed_J);
}

TEST(Forest, ASpeciesOfLargerBreakingEnergyStopsTheCubeTheDefaultLetsThrough) {
  // The 20 cm stem that the cube breaks above (E_max = 39 kJ < 62 kJ at the stem), of a species
  // with a law of its own: coefficient 80 J, the forest's exponent 2.31: E_max = 80.7 kJ. The cube
  // is stopped against it, as against the 40 cm stem of the default law above (same tolerances:
  // 0.02 m of detection lag).
  Scene scene = SlidingScene();
  const double m = scene.rock.mass_kg;
  TreeSpecies oak;
  oak.name = "oak";
  oak.energy_coefficient_J = 80;
  scene.forest = OneStemOfSpecies(oak);
  const BreakingLaw law = scene.forest.model().Law(0);
  EXPECT_EQ(law.factor, 1);
  EXPECT_EQ(law.coefficient_J, 80);
  EXPECT_EQ(law.exponent, ForestModel{}.energy_exponent);
  EXPECT_NEAR(scene.forest.capacity_J(0), 80 * std::pow(20.0, 2.31), 1e-9);
  SimulationWorkspace ws;
  const RockResult r = SimulateRock(scene, SlidingStart(scene), ws);
  ASSERT_EQ(r.end, EndReason::kRest);
  ASSERT_EQ(r.stem_hits.size(), 1u);
  EXPECT_FALSE(r.stem_hits[0].broken);
  const double contact_x = 26 - 0.1 - 0.5 * kSide_m;
  EXPECT_NEAR(r.final_state.position_m.x(), contact_x, 0.02);
  const double expected = 0.5 * m * 100 - kMu * m * kG * (contact_x - 20);
  EXPECT_LT(expected, scene.forest.capacity_J(0));
  EXPECT_GT(expected, ForestModel{}.BreakingEnergy_J(0.2));  // the default law's stem breaks
  EXPECT_NEAR(r.stem_hits[0].energy_J, expected, kMu * m * kG * 0.02);
  // The stem took all of it, and the little of the cube settling against it after the stop (the
  // same episode; measured 0.07 J, 1e-6 of it): 1e-5 relative.
  EXPECT_NEAR(r.stem_hits[0].absorbed_J, r.stem_hits[0].energy_J, 1e-5 * r.stem_hits[0].energy_J);
}

TEST(Forest, SpeciesAreChecked) {
  ForestModel model;
  std::string why;
  TreeSpecies s;
  s.name = "beech";
  s.energy_factor = 0;
  model.species = {s};
  EXPECT_FALSE(model.IsValid(&why));
  EXPECT_NE(why.find("species 'beech': energy_factor = 0 must be finite and > 0"),
            std::string::npos)
      << why;
  model.species[0].energy_factor = 2;
  model.species[0].energy_coefficient_J = 60;
  EXPECT_FALSE(model.IsValid(&why));
  EXPECT_NE(why.find("not both"), std::string::npos) << why;
  model.species[0].energy_factor = 1;
  EXPECT_TRUE(model.IsValid(&why)) << why;
  model.species[0].name = "be\nech";
  model.species[0].name[2] = '\n';
  EXPECT_FALSE(model.IsValid(&why));
  EXPECT_NE(why.find("control characters"), std::string::npos) << why;
  model.species[0].name = "beech";
  const Forest unknown({Stem{{0, 0}, 0.2, 0, 1}}, model);
  EXPECT_FALSE(unknown.IsValid(&why));
  EXPECT_NE(why.find("species 1"), std::string::npos) << why;
}

TEST(Forest, ARockAboveTheStemsTopPassesBitForBitUnchanged) {
  Scene scene = SlidingScene();
  RockState s;
  s.position_m = {20, 0, 15};
  s.velocity_m_s = {10, 0, 0};
  SimulationWorkspace ws;
  scene.options.max_time_s = 0.5;
  const RockResult free = SimulateRock(scene, s, ws);
  scene.forest = OneStem(23, 0, 0.5);  // 10 m stems; the cube's lowest vertex stays above 13.2 m
  const RockResult r = SimulateRock(scene, s, ws);
  EXPECT_TRUE(r.stem_hits.empty());
  EXPECT_EQ(r.final_state.position_m, free.final_state.position_m);
  EXPECT_EQ(r.final_state.velocity_m_s, free.final_state.velocity_m_s);
}

// The forest as a drag layer (ForestDrag; docs/model.md, "Forest as a drag layer"): on the
// scene's DEM grid, the cells whose centres lie in [x0, x1] x [y0, y1] hold one stand of n stems
// per hectare of DBH D, E_max(D) by the default ForestModel, 10 m high.
ForestDrag Stand(const Scene& scene, double x0, double x1, double y0, double y1,
                 double stems_per_ha, double dbh_m) {
  const GridGeometry& grid = scene.terrain.heights().grid;
  std::vector<int> cells(static_cast<std::size_t>(grid.nx) * grid.ny, -1);
  for (int j = 0; j < grid.ny; ++j)
    for (int i = 0; i < grid.nx; ++i) {
      const double x = grid.x0_m + i * grid.dx_m, y = grid.y0_m + j * grid.dy_m;
      if (x >= x0 && x <= x1 && y >= y0 && y <= y1)
        cells[static_cast<std::size_t>(j) * grid.nx + i] = 0;
    }
  const ForestModel model;
  return ForestDrag(grid, std::move(cells),
                    {DragStand{stems_per_ha / 1e4, dbh_m, model.BreakingEnergy_J(dbh_m)}},
                    model.stem_height_m);
}

TEST(ForestDrag, UniformStandSlowsAFlyingRockAsTheDerivationSays) {
  // No gravity; the 1 m cube (m = 2700 kg, w = (6 / pi)^(1/3) = 1.2407 m) flies along +x 1 m
  // above flat ground through a stand of n = 400 /ha, D = 30 cm (E_max = 99.96 kJ): lambda =
  // n (D + w) = 0.06163 stems per metre. Pure translation, E = m v^2 / 2, so dv/dt = -lambda dE /
  // m:
  // - above v* = sqrt(2 E_max / (eta m)) = 10.54 m/s every hit breaks its stem and takes E_max:
  //   dv/dt = -a, a = lambda E_max / m = 2.28 m/s^2, v = v0 - a t;
  // - below it each hit takes eta E: dv/dt = -k v^2, k = lambda eta / 2, v = v* / (1 + k v* t').
  // The scheme freezes the rate at each step's beginning and integrates it exactly over the step:
  // per step it keeps v e^(-y) - (v - a dt) <= v y^2 / 2 = a^2 dt^2 / (2 v) too much above v*
  // (y = a dt / v) and v (e^(-y) - 1 / (1 + y)) >= -v y^2 / 2 below it (y = k v dt); the first
  // summed over the T* = 4.2 s above v* is at most a^2 dt T* / (2 v*) = 2.1e-3 m/s, the second
  // under 1e-4 m/s. Tolerance 3e-3 m/s. Spinning about a principal axis (the cube's are all
  // principal, free rotation keeps Omega), Omega decays at the same rate: Omega / |v| stays.
  Scene scene = scenes::Incline(0, Cube(), GroundParams{kMu, kMu, 150, 2, 0});
  scene.options.gravity_m_s2 = 0;
  scene.forest_drag = Stand(scene, 0, 200, -100, 100, 400, 0.30);
  std::string why;
  ASSERT_TRUE(scene.IsValid(&why)) << why;
  const double m = scene.rock.mass_kg, dt = scene.options.dt_s;
  const double w = std::cbrt(6 / std::numbers::pi), e_max = ForestModel{}.BreakingEnergy_J(0.30);
  EXPECT_NEAR(ForestDrag::RockWidth_m(scene.rock), w, 1e-12);
  const double lambda = 0.04 * (0.30 + w), eta = 2.0 / 3.0;
  const double a = lambda * e_max / m, v_star = std::sqrt(2 * e_max / (eta * m));
  const double k = lambda * eta / 2, v0 = 20, t_star = (v0 - v_star) / a;
  auto exact = [&](double t) {
    return t <= t_star ? v0 - a * t : v_star / (1 + k * v_star * (t - t_star));
  };
  for (double spin : {0.0, 2.0}) {
    StepWorkspace ws;
    ws.Reset(scene.rock.vertices_m.size());
    RockState s;
    s.position_m = {10, 0, 1};
    s.velocity_m_s = {v0, 0, 0};
    s.angular_velocity_rad_s = {0, 0, spin};
    int steps = 0;
    for (double t : {1.0, 3.0, 4.0, 6.0, 8.0}) {
      for (; steps < std::lround(t / dt); ++steps) Step(scene, s, ws);
      SCOPED_TRACE("spin " + std::to_string(spin) + ", t = " + std::to_string(t));
      if (spin == 0) {
        EXPECT_NEAR(s.velocity_m_s.x(), exact(t), 3e-3);
      } else {
        // The rotational energy lowers the rate above v* (E_max is shared) and not below it.
        EXPECT_GT(s.velocity_m_s.x(), exact(t) - 3e-3);
        EXPECT_NEAR(s.angular_velocity_rad_s.z() / s.velocity_m_s.x(), spin / v0, 1e-12);
      }
      EXPECT_EQ(s.velocity_m_s.y(), 0);
      EXPECT_EQ(s.velocity_m_s.z(), 0);
    }
  }
  // The same rock standing still in the stand, or falling straight down, meets no stem.
  RockState still;
  still.angular_velocity_rad_s = {0, 0, 3};
  EXPECT_EQ(ForestDrag::Rate_1_s(scene.forest_drag.stands()[0], scene.rock, still), 0);
  still.velocity_m_s = {0, 0, -5};
  EXPECT_EQ(ForestDrag::Rate_1_s(scene.forest_drag.stands()[0], scene.rock, still), 0);
}

TEST(ForestDrag, ActsOnlyInsideItsStandsAndBelowItsHeight) {
  Scene scene = scenes::Incline(0, Cube(), GroundParams{kMu, kMu, 150, 2, 0});
  scene.forest_drag = Stand(scene, 50, 100, -20, 20, 400, 0.30);  // cells of 5 m: edges +-2.5 m
  const ForestDrag& drag = scene.forest_drag;
  RockState moving;
  moving.velocity_m_s = {10, 0, 0};
  EXPECT_GT(ForestDragRate_1_s(drag, scene.rock, moving, {75, 0, 1}, 1.0), 0);
  EXPECT_GT(ForestDragRate_1_s(drag, scene.rock, moving, {75, 0, 10}, 10.0), 0);
  EXPECT_EQ(ForestDragRate_1_s(drag, scene.rock, moving, {75, 0, 10.01}, 10.01), 0);
  EXPECT_GT(ForestDragRate_1_s(drag, scene.rock, moving, {47.6, 22.4, 1}, 1.0), 0);
  EXPECT_EQ(ForestDragRate_1_s(drag, scene.rock, moving, {47.4, 0, 1}, 1.0), 0);
  EXPECT_EQ(ForestDragRate_1_s(drag, scene.rock, moving, {75, 22.6, 1}, 1.0), 0);
  EXPECT_EQ(ForestDragRate_1_s(drag, scene.rock, moving, {-75, 0, 1}, 1.0), 0);  // off the grid
}

TEST(ForestDrag, ARockOutsideTheStandsRunsBitForBitAsWithoutForest) {
  // A cube tumbling down a 35 deg slope near y = 0 (released with its faces along the axes and
  // spinning about y: it strays less than 5 m from y = 0), with and without a stand
  // beside its path (y >= 40 m) and a drag layer in that stand that also shortens the flight
  // windows: the same state bit for bit. The stand across its path does change it.
  Scene scene = scenes::Incline(35, Cube(), GroundParams{0.35, 2.0, 150, 2, 0.6});
  scene.options.max_time_s = 6;
  RockState s;
  s.position_m = {20, 0, 0};
  s.velocity_m_s = {3, 0, 0};
  s.angular_velocity_rad_s = {0, 2, 0};
  TerrainSample ground;
  ASSERT_TRUE(scene.terrain.Sample(20, 0, &ground));
  s.position_m.z() = ground.height_m + 1.5;
  SimulationWorkspace ws;
  const RockResult free = SimulateRock(scene, s, ws);
  EXPECT_LT(std::abs(free.final_state.position_m.y()), 5);
  EXPECT_GT(free.final_state.position_m.x(), 40);
  scene.forest_drag = Stand(scene, 0, 200, 40, 100, 400, 0.30);
  const RockResult beside = SimulateRock(scene, s, ws);
  EXPECT_EQ(beside.final_state.position_m, free.final_state.position_m);
  EXPECT_EQ(beside.final_state.velocity_m_s, free.final_state.velocity_m_s);
  EXPECT_EQ(beside.final_state.angular_velocity_rad_s, free.final_state.angular_velocity_rad_s);
  EXPECT_EQ(beside.steps, free.steps);
  scene.forest_drag = Stand(scene, 0, 200, -20, 20, 400, 0.30);
  const RockResult across = SimulateRock(scene, s, ws);
  EXPECT_GT((across.final_state.position_m - free.final_state.position_m).norm(), 1);
}

}  // namespace
}  // namespace talus
