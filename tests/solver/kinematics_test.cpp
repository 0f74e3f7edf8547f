// Free flight and torque-free rotation: the kinematic stages and the step without contacts.

#include "solver/kinematics.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "scenes/scenes.hpp"
#include "solver/shapes.hpp"
#include "solver/simulate.hpp"
#include "solver/step.hpp"

namespace talus {
namespace {

// A scene whose terrain is far below the rock, so every step is free flight.
Scene FlightScene(const RockShape& rock, double gravity) {
  Scene scene = scenes::Incline(0.0, rock, GroundParams{}, 200, 10);
  scene.options.gravity_m_s2 = gravity;
  return scene;
}

RockShape Cuboid123() { return MakeRockShape(MakeBox(1, 2, 3), 2700); }

Eigen::Vector3d AngularMomentumWorld(const RockShape& rock, const RockState& s) {
  return s.orientation * rock.inertia_kg_m2.cwiseProduct(s.angular_velocity_rad_s);
}

TEST(FreeFlight, FollowsTheParabolaAndKeepsEnergy) {
  // Closed form: r(t) = r0 + v0 t - g t^2/2 e_z. The midpoint scheme is exact for constant
  // acceleration, so the tolerance is round-off (1e-9 relative).
  const Scene scene = FlightScene(Cuboid123(), 9.81);
  RockState s;
  s.position_m = {50, 0, 1000};
  s.velocity_m_s = {12, -3, 20};
  s.angular_velocity_rad_s = {0.4, -2.0, 1.1};
  const RockState s0 = s;
  const double e0 = KineticEnergy(scene.rock, s) + scene.rock.mass_kg * 9.81 * s.position_m.z();
  StepWorkspace ws;
  ws.Reset(scene.rock.vertices_m.size());
  for (int k = 0; k < 2000; ++k) ASSERT_EQ(Step(scene, s, ws).contacts, 0);
  const double t = s.time_s;
  EXPECT_NEAR(t, 4.0, 1e-12);
  const Eigen::Vector3d expected =
      s0.position_m + t * s0.velocity_m_s - 0.5 * 9.81 * t * t * Eigen::Vector3d::UnitZ();
  EXPECT_LT((s.position_m - expected).norm(), 1e-9 * expected.norm());
  const double e1 = KineticEnergy(scene.rock, s) + scene.rock.mass_kg * 9.81 * s.position_m.z();
  EXPECT_NEAR(e1, e0, 1e-9 * e0);
}

TEST(FreeRotation, CuboidConservesEnergyAndAngularMomentumOver1e5Steps) {
  // Implicit midpoint conserves both quadratic invariants exactly; required: 1e-9 relative over
  // 1e5 steps at dt = 2 ms (Leine et al. 2021, Sec. 4). Measured: 1e-14 for both; the direction
  // of the world angular momentum, which the orientation update does not conserve exactly, turns
  // by 9e-7 rad over the 200 s.
  const Scene scene = FlightScene(Cuboid123(), 0.0);
  RockState s;
  s.position_m = {50, 0, 1000};
  s.angular_velocity_rad_s = {1.3, -0.7, 2.1};
  const double e0 = KineticEnergy(scene.rock, s);
  const double l0 = AngularMomentumWorld(scene.rock, s).norm();
  StepWorkspace ws;
  ws.Reset(scene.rock.vertices_m.size());
  for (int k = 0; k < 100000; ++k) Step(scene, s, ws);
  EXPECT_NEAR(KineticEnergy(scene.rock, s), e0, 1e-9 * e0);
  EXPECT_NEAR(AngularMomentumWorld(scene.rock, s).norm(), l0, 1e-9 * l0);
}

// Largest angle (deg) between the body angular momentum and principal axis `axis` over 100 s
// when spinning at 2 rad/s about that axis with a 1e-3 perturbation on the other two.
double MaxDeviationDeg(int axis) {
  const Scene scene = FlightScene(Cuboid123(), 0.0);
  RockState s;
  s.position_m = {50, 0, 1000};
  s.angular_velocity_rad_s = Eigen::Vector3d::Constant(2e-3);
  s.angular_velocity_rad_s[axis] = 2.0;
  StepWorkspace ws;
  ws.Reset(scene.rock.vertices_m.size());
  double max_angle = 0;
  for (int k = 0; k < 50000; ++k) {
    Step(scene, s, ws);
    const Eigen::Vector3d l = scene.rock.inertia_kg_m2.cwiseProduct(s.angular_velocity_rad_s);
    max_angle = std::max(max_angle, std::acos(std::abs(l[axis]) / l.norm()) * 180 / M_PI);
    if (l[axis] < 0) return 180;  // flipped
  }
  return max_angle;
}

TEST(FreeRotation, MajorAndMinorAxesAreStable) {
  // Euler's equations: rotation about the axes of largest and smallest inertia is stable; the
  // 1e-3 perturbation must stay within a few degrees (here: 3) for 100 s.
  EXPECT_LT(MaxDeviationDeg(2), 3.0);  // major axis (largest moment)
  EXPECT_LT(MaxDeviationDeg(0), 3.0);  // minor axis
}

TEST(FreeRotation, IntermediateAxisFlips) {
  // Tennis-racket theorem: rotation about the intermediate axis is unstable and flips.
  EXPECT_EQ(MaxDeviationDeg(1), 180.0);
}

TEST(FreeRotation, AStepOfManyRadiansStillConservesBothInvariants) {
  // The implicit midpoint rule keeps kinetic energy and |angular momentum| exactly for any step
  // (Leine et al. 2021, Sec. 4); required 1e-9 relative. dt |W| = 10 (dt 0.1 s, the largest the
  // options allow, at 100 rad/s) on the 1 x 2 x 3 cuboid: Newton's method from W_b fails to
  // converge on 36 of these 400 rates, which the halving must catch (before it, 2233 of 20000
  // random rates on a 45:80:110 inertia came back changed in energy, some 180-fold).
  const RockShape rock = Cuboid123();
  const Eigen::Vector3d& theta = rock.inertia_kg_m2;
  int checked = 0;
  for (int i = 0; i < 400; ++i) {
    const double a = 0.7 * i, b = 1.3 * i + 0.4;
    const Eigen::Vector3d w =
        100.0 * Eigen::Vector3d(std::cos(a) * std::sin(b), std::sin(a) * std::sin(b), std::cos(b));
    const Eigen::Vector3d f = FreeRotation(theta, w, 0.1);
    const double e0 = w.dot(theta.cwiseProduct(w));
    const double l0 = theta.cwiseProduct(w).norm();
    ASSERT_NEAR(f.dot(theta.cwiseProduct(f)), e0, 1e-9 * e0) << "rate " << w.transpose();
    ASSERT_NEAR(theta.cwiseProduct(f).norm(), l0, 1e-9 * l0) << "rate " << w.transpose();
    ++checked;
  }
  EXPECT_EQ(checked, 400);
}

TEST(Drift, RotatesByTheExactAngle) {
  // A constant body rate w over h rotates by |w| h about w.
  RockState s;
  s.angular_velocity_rad_s = {0, 0, 0.5};
  Drift(s, 2.0);
  EXPECT_NEAR(s.orientation.angularDistance(
                  Eigen::Quaterniond(Eigen::AngleAxisd(1.0, Eigen::Vector3d::UnitZ()))),
              0.0, 1e-14);
}

TEST(Drift, AKeptTurnGivesTheSameBitsAsOneComputedAfresh) {
  // The step reuses the end drift's turn at the next midpoint (DriftTurn): the orientation must
  // be the same bits as without it, through rate changes, repeats, a zero and a signed zero.
  RockState kept, fresh;
  kept.orientation = fresh.orientation = Eigen::Quaterniond(0.3, -0.5, 0.7, 0.1).normalized();
  DriftTurn turn;
  const Eigen::Vector3d rates[] = {{1.3, -0.7, 2.1}, {1.3, -0.7, 2.1}, {0, 0, 0},
                                   {0, 0, 0},        {-0.0, 0.2, 0},   {0.0, 0.2, 0},
                                   {5.5, 0.1, -3.0}, {5.5, 0.1, -3.0}};
  int step = 0;
  for (const Eigen::Vector3d& w : rates) {
    for (double h : {0.001, 0.001, 0.00025}) {
      kept.angular_velocity_rad_s = fresh.angular_velocity_rad_s = w;
      Drift(kept, h, &turn);
      Drift(fresh, h);
      ASSERT_EQ(kept.orientation.coeffs(), fresh.orientation.coeffs()) << "drift " << step;
      ++step;
    }
  }
}

}  // namespace
}  // namespace talus
