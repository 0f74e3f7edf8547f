// Rolling on hard ground: a polygonal prism rolling down an incline is a rimless wheel (McGeer
// 1990, "Passive dynamic walking", Int. J. Robotics Research 9(2)), whose steady gait and whose
// stopping have closed forms. The seed's contact law (plastic impacts, Coulomb friction) gives
// exactly that wheel when no vertex slips: between impacts the prism pivots about its lowest edge,
// and each impact on the next edge keeps the angular momentum about that edge.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <utility>

#include "scenes/scenes.hpp"
#include "solver/shapes.hpp"
#include "solver/step.hpp"

namespace talus {
namespace {

constexpr double kG = 9.81;
constexpr double kDeg = std::numbers::pi / 180;

// A prism over a regular n-gon (circumradius l, axis across the slope), mass m and centroidal
// inertia I_c about its axis, pivoting about an edge: I_p = I_c + m l^2. Half the angle between
// neighbouring spokes alpha = pi / n. McGeer's wheel on a slope gamma:
// - stance: I_p phi'' = m g l sin(phi), phi the spoke's angle from the vertical, from gamma - alpha
//   to gamma + alpha, so (energy) w_end^2 = w_start^2 + (4 m g l / I_p) sin(gamma) sin(alpha);
// - impact (plastic, no slip, angular momentum about the new pivot kept):
//   I_p w+ = (I_c + m l^2 cos(2 alpha)) w-, w+ = eta w-;
// - steady gait: w_end^2 = 4 m g l sin(gamma) sin(alpha) / (I_p (1 - eta^2));
// - it exists only where the wheel, starting a stance at eta w_end, passes over the top:
//   I_p (eta w_end)^2 / 2 > m g l (1 - cos(alpha - gamma)) for gamma < alpha.
struct Wheel {
  double m, inertia_c, l, alpha;
  double InertiaPivot() const { return inertia_c + m * l * l; }
  double Eta() const { return (inertia_c + m * l * l * std::cos(2 * alpha)) / InertiaPivot(); }
  double SteadyEndSpeed(double gamma) const {
    const double eta = Eta();
    return std::sqrt(4 * m * kG * l * std::sin(gamma) * std::sin(alpha) /
                     (InertiaPivot() * (1 - eta * eta)));
  }
  bool SteadyGaitExists(double gamma) const {
    const double start = Eta() * SteadyEndSpeed(gamma);
    return gamma >= alpha ||
           0.5 * InertiaPivot() * start * start > m * kG * l * (1 - std::cos(alpha - gamma));
  }
};

struct Prism {
  Scene scene;
  Wheel wheel;
  Eigen::Quaterniond axis_across;  // shape frame (axis z) -> world (axis y)
};

Prism MakePrism(int sides, double slope_deg, double dt_s) {
  const double l = 0.6, thickness = 1.0;
  GroundParams ground{1.0, 1.0, 150, 2.0, 0.0};  // mu = 1 everywhere: no slip at the pivot
  Prism p{scenes::Incline(slope_deg, MakeRockShape(MakeCylinder(l, thickness, sides), 2700), ground,
                          400, 5),
          {},
          Eigen::Quaterniond(Eigen::AngleAxisd(std::numbers::pi / 2, Eigen::Vector3d::UnitX()))};
  p.scene.options.dt_s = dt_s;
  p.scene.options.tolerance_m_s = 1e-12;
  const RockShape& rock = p.scene.rock;
  // The prism's axis is the principal axis whose inertia differs from the other two.
  double axis_inertia = rock.inertia_kg_m2.x();
  for (int k = 0; k < 3; ++k)
    if (std::abs(rock.inertia_kg_m2[k] - rock.inertia_kg_m2[(k + 1) % 3]) > 1e-6 &&
        std::abs(rock.inertia_kg_m2[k] - rock.inertia_kg_m2[(k + 2) % 3]) > 1e-6)
      axis_inertia = rock.inertia_kg_m2[k];
  p.wheel = {rock.mass_kg, axis_inertia, l, std::numbers::pi / sides};
  return p;
}

// Rolls the prism, its axis across the slope, from its lowest edge touching at angular speed w0
// (rolling down +x) for `seconds`. Returns the largest |omega| of the step ends in the last
// window_s, and whether it came to rest (speed below 1e-3 m/s and angular speed below 1e-3 rad/s
// at the end).
struct Rolled {
  double max_omega = 0;
  bool at_rest = false;
  double distance_m = 0;
};
Rolled Roll(const Prism& p, double w0, double seconds, double window_s) {
  StepWorkspace ws;
  ws.Reset(p.scene.rock.vertices_m.size());
  RockState s;
  s.orientation = p.scene.rock.PrincipalOrientation(p.axis_across);
  TerrainSample ground;
  p.scene.terrain.Sample(50, 0, &ground);
  s.position_m = {50, 0, ground.height_m + 2};
  double min_gap = 1e9;
  for (const auto& b : p.scene.rock.vertices_m) {
    const Eigen::Vector3d v = s.position_m + s.orientation * b;
    TerrainSample at;
    p.scene.terrain.Sample(v.x(), v.y(), &at);
    min_gap = std::min(min_gap, (v.z() - at.height_m) * ground.normal.z());
  }
  s.position_m.z() -= (min_gap + 1e-9) / ground.normal.z();
  s.angular_velocity_rad_s = s.orientation.inverse() * Eigen::Vector3d(0, w0, 0);
  const Eigen::Vector3d start = s.position_m;
  const int steps = static_cast<int>(std::lround(seconds / p.scene.options.dt_s));
  const int window = static_cast<int>(std::lround(window_s / p.scene.options.dt_s));
  Rolled r;
  for (int k = 0; k < steps; ++k) {
    EXPECT_FALSE(Step(p.scene, s, ws).outside_domain) << "the prism left the incline";
    if (k >= steps - window) r.max_omega = std::max(r.max_omega, s.angular_velocity_rad_s.norm());
  }
  r.at_rest = s.velocity_m_s.norm() < 1e-3 && s.angular_velocity_rad_s.norm() < 1e-3;
  r.distance_m = (s.position_m - start).norm();
  return r;
}

// The lowest slope with a steady gait (bisection on SteadyGaitExists, which is monotone in gamma).
double CriticalSlope(const Wheel& wheel) {
  double lo = 1e-6, hi = wheel.alpha;
  for (int k = 0; k < 60; ++k) {
    const double mid = 0.5 * (lo + hi);
    (wheel.SteadyGaitExists(mid) ? hi : lo) = mid;
  }
  return hi;
}

TEST(RimlessWheel, OctagonalPrismReachesMcGeersSteadyGait) {
  // An octagonal prism (circumradius 0.6 m, 1 m long, 2700 kg/m^3, mu = 1: no vertex slips),
  // started at 2 rad/s, rolls 20 s; the largest step-end |omega| of the last 2 s is the gait's
  // speed just before an impact, w_end. The closed form holds while the pivot stays loaded:
  // w^2 l <= g cos(phi) up to phi = gamma + alpha (checked; on 20 deg the prism hops, and the
  // wheel's law does not apply). Tolerance 2 w' dt with w' = m g l sin(gamma + alpha) / I_p, the
  // largest angular acceleration of a stance: the step ends sample w_end at most w' dt early (one
  // w' dt, derived); the second w' dt is a margin for the impact step, whose percussion acts at the
  // step's midpoint configuration up to half a step off the contact's instant, an error of first
  // order in dt whose constant is not derived here. Measured: -0.07 % and +0.14 % of w_end on 6 and
  // 12 deg at dt 2 ms (tolerances 0.96 % and 0.81 %), +0.01 % and +0.08 % at 0.5 ms.
  for (double slope : {6.0, 12.0}) {
    for (double dt : {0.002, 0.0005}) {
      const Prism p = MakePrism(8, slope, dt);
      const Wheel& w = p.wheel;
      const double gamma = slope * kDeg;
      const double expected = w.SteadyEndSpeed(gamma);
      ASSERT_TRUE(w.SteadyGaitExists(gamma));
      ASSERT_LE(expected * expected * w.l, kG * std::cos(gamma + w.alpha)) << "the prism hops";
      const double acceleration = w.m * kG * w.l * std::sin(gamma + w.alpha) / w.InertiaPivot();
      const Rolled r = Roll(p, 2.0, 20.0, 2.0);
      std::printf(
          "slope %4.1f deg, dt %.4f s: w_end %.4f rad/s, McGeer %.4f (%+.2f %%, tolerance "
          "%.2f %%)\n",
          slope, dt, r.max_omega, expected, 100 * (r.max_omega / expected - 1),
          100 * 2 * acceleration * dt / expected);
      EXPECT_NEAR(r.max_omega, expected, 2 * acceleration * dt) << slope << " deg, dt " << dt;
    }
  }
}

TEST(RimlessWheel, OctagonalPrismStopsBelowTheCriticalSlopeAndRollsOnAbove) {
  // Below the critical slope no steady gait exists: every stance starts slower than the last
  // (McGeer), and the wheel, rocking back at last, comes to rest by its impacts alone. Just above
  // it, the gait exists and a prism started at the gait's own speed keeps rolling. The critical
  // slope of this prism is 2.56 deg (printed); tested 0.5 deg either side, 60 s at dt 2 ms.
  const Prism probe = MakePrism(8, 0, 0.002);
  const double critical = CriticalSlope(probe.wheel) / kDeg;
  std::printf("critical slope %.3f deg\n", critical);
  ASSERT_GT(critical, 1.0);
  ASSERT_LT(critical, 5.0);
  {
    const Prism p = MakePrism(8, critical - 0.5, 0.002);
    const Rolled r = Roll(p, p.wheel.Eta() * p.wheel.SteadyEndSpeed(critical * kDeg), 60.0, 1.0);
    std::printf("%.2f deg: at rest %d after %.2f m\n", critical - 0.5, r.at_rest, r.distance_m);
    EXPECT_TRUE(r.at_rest);
    EXPECT_LT(r.distance_m, 10.0);
  }
  {
    const double slope = critical + 0.5;
    const Prism p = MakePrism(8, slope, 0.002);
    const double w_end = p.wheel.SteadyEndSpeed(slope * kDeg);
    const Rolled r = Roll(p, p.wheel.Eta() * w_end, 60.0, 2.0);
    std::printf("%.2f deg: at rest %d after %.2f m, w_end %.4f (McGeer %.4f)\n", slope, r.at_rest,
                r.distance_m, r.max_omega, w_end);
    EXPECT_FALSE(r.at_rest);
    EXPECT_GT(r.distance_m, 20.0);
  }
}

}  // namespace
}  // namespace talus

namespace talus {
namespace {

// Impact sub-steps (SolverOptions::impact_substeps): a step whose contact set holds a predicted
// contact (with substep_impacts "all", also a new contact) is, bit for bit, that many steps of
// dt / impact_substeps; every other step is one step of dt as without the option.
TEST(ImpactSubsteps, ASplitStepIsExactlyItsSubSteps) {
  for (const auto& [k, impacts] : {std::pair{2, SubstepImpacts::kFast},
                                   {4, SubstepImpacts::kFast},
                                   {4, SubstepImpacts::kAll}}) {
    Prism split = MakePrism(8, 12, 0.002);
    split.scene.options.impact_substeps = k;
    split.scene.options.substep_impacts = impacts;
    Prism fine = MakePrism(8, 12, 0.002 / k);
    StepWorkspace ws_split, ws_fine, ws_plain;
    ws_split.Reset(split.scene.rock.vertices_m.size());
    ws_fine.Reset(fine.scene.rock.vertices_m.size());
    ws_plain.Reset(split.scene.rock.vertices_m.size());
    Prism plain = MakePrism(8, 12, 0.002);
    // "all" goes with held contacts (io/scene_file.cpp): all three hold.
    const ContactHold hold =
        impacts == SubstepImpacts::kAll ? ContactHold::kHeld : ContactHold::kMidpoint;
    for (Prism* p : {&split, &fine, &plain}) p->scene.options.contact_hold = hold;
    RockState s;
    s.orientation = split.scene.rock.PrincipalOrientation(split.axis_across);
    TerrainSample ground;
    split.scene.terrain.Sample(50, 0, &ground);
    // Its lowest edge falls 3.4 m onto the slope and lands at 8.2 m/s: beyond the 1 cm it may sink
    // (the penetration tolerance, 1 % of its 1 m length) within a step, so the landing is a
    // predicted contact; then it rolls, its edges arriving slowly enough to be found closed.
    s.position_m = {50, 0, ground.height_m + 4.0};
    s.angular_velocity_rad_s = s.orientation.inverse() * Eigen::Vector3d(0, 2.0, 0);
    int splits = 0, singles = 0;
    for (int step = 0; step < 1500; ++step) {
      RockState a = s, b = s, c = s;
      // The same warm start for all three: each workspace follows its own run from s.
      const StepReport r = Step(split.scene, a, ws_split);
      if (r.substeps == k) {
        ++splits;
        for (int i = 0; i < k; ++i) Step(fine.scene, b, ws_fine);
        ASSERT_EQ(a.position_m, b.position_m) << "step " << step;
        ASSERT_EQ(a.velocity_m_s, b.velocity_m_s) << "step " << step;
        ASSERT_EQ(a.angular_velocity_rad_s, b.angular_velocity_rad_s) << "step " << step;
        ASSERT_EQ(a.orientation.coeffs(), b.orientation.coeffs()) << "step " << step;
        ASSERT_EQ(a.scar_m, b.scar_m) << "step " << step;
        ASSERT_EQ(a.scar_ground, b.scar_ground) << "step " << step;
        ASSERT_EQ(a.time_s, s.time_s + 0.002) << "step " << step;  // one step, whatever its parts
        Step(plain.scene, c, ws_plain);  // keep the plain workspace in step
      } else {
        ++singles;
        ASSERT_EQ(r.substeps, 1);
        Step(plain.scene, c, ws_plain);
        ASSERT_EQ(a.position_m, c.position_m) << "step " << step;
        ASSERT_EQ(a.velocity_m_s, c.velocity_m_s) << "step " << step;
        ASSERT_EQ(a.angular_velocity_rad_s, c.angular_velocity_rad_s) << "step " << step;
        ASSERT_EQ(a.scar_m, c.scar_m) << "step " << step;
        ASSERT_EQ(a.time_s, c.time_s) << "step " << step;
        for (int i = 0; i < k; ++i) Step(fine.scene, b, ws_fine);  // keep the fine one in step
      }
      s = a;
      ws_fine = ws_split;
      ws_plain = ws_split;
    }
    std::printf("impact_substeps %d, substep_impacts %s: %d split steps, %d single steps\n", k,
                ToString(impacts), splits, singles);
    EXPECT_GE(splits, 1);      // the landing
    EXPECT_GT(singles, 1000);  // the fall and the rolling
    // "all": also the steps in which the prism's next edge arrives as it rolls (7 split steps).
    if (impacts == SubstepImpacts::kAll) {
      EXPECT_GE(splits, 4);
    }
  }
}

}  // namespace
}  // namespace talus
