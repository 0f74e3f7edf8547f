// The contact solve stage (solver/contact_solver.hpp) on contacts built by hand: a single
// contact's plastic impact, Coulomb sticking and sliding, Newton's restitution, a predicted
// contact's gap law and the contact-friction viscous term against their closed forms; with a lever
// arm, against the invariants of an impulsive contact (angular momentum about the contact point
// is conserved, the contact point stops when it sticks, a slipping contact's friction opposes
// the slip at the cone's edge); and two symmetric contacts solved by Gauss-Seidel sweeps and by
// the block method. (contact_block_test.cpp compares the two methods on random edges.)

#include "solver/contact_solver.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "solver/shapes.hpp"

namespace talus {
namespace {

constexpr double kMass = 2500 * 1.2 * 0.8 * 0.5;  // the rock below: 1.2 x 0.8 x 0.5 m, 2500 kg/m^3

// A contact frame tilted by 30 degrees about y: columns n, t1, t2.
Eigen::Matrix3d TiltedFrame() {
  const double a = std::numbers::pi / 6;
  Eigen::Matrix3d d;
  d.col(0) = Eigen::Vector3d(std::sin(a), 0, std::cos(a));
  d.col(1) = Eigen::Vector3d(std::cos(a), 0, -std::sin(a));
  d.col(2) = Eigen::Vector3d::UnitY();
  return d;
}

// One rock, one scene and the contacts of one step. The viscous term acts on the centre of mass
// (outside the contact solve) unless a test asks for the contact-friction reading; the solve is
// tight so that closed forms hold to round-off.
struct Fixture {
  Scene scene;
  RockShape rock = MakeRockShape(MakeBox(1.2, 0.8, 0.5), 2500);
  StepWorkspace ws;
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d v = Eigen::Vector3d::Zero(), w = Eigen::Vector3d::Zero();

  Fixture() {
    scene.options.viscous = ViscousReading::kCentreOfMass;
    scene.options.tolerance_m_s = 1e-12;
    scene.options.max_iterations = 100000;
    ws.Reset(rock.vertices_m.size());
  }
  Contact& Add(const Eigen::Vector3d& lever, double mu, const Eigen::Matrix3d& frame,
               double gap = 0) {
    Contact& c = ws.contacts.emplace_back();
    c.vertex = static_cast<int>(ws.contacts.size()) - 1;
    c.lever_m = lever;
    c.mu = mu;
    c.directions = frame;
    c.gap_m = gap;
    return c;
  }
  // Solves with (v, w) as both the begin and the free end velocities (an impulsive impact).
  ContactSolveReport Solve(double mass_kg = 0) {
    return SolveContacts(scene, rock, scene.options.dt_s, rotation,
                         {mass_kg > 0 ? mass_kg : rock.mass_kg, 1.0}, v, w, v, w, ws);
  }
};

// A contact at the centre of mass (no lever: G = I / m). Plastic, approaching at v_N with
// tangential speed v_T: it sticks (end velocity 0, P = -m v) when |v_T| <= mu v_N, else it slides
// on with v_T (1 - mu v_N / |v_T|) in the same direction, P_N = m v_N, |P_T| = mu P_N. One sweep
// solves it exactly (tolerance 1e-12 m/s relative to the speeds).
TEST(SolveContacts, PointContactSticksOrSlidesByCoulomb) {
  const Eigen::Matrix3d frame = TiltedFrame();
  const double mu = 0.6, vn = 2.0;
  for (double ratio : {0.0, 0.3, 0.99, 1.01, 1.5, 4.0}) {  // |v_T| / (mu v_N)
    Fixture f;
    f.Add(Eigen::Vector3d::Zero(), mu, frame);
    ASSERT_NEAR(f.rock.mass_kg, kMass, 1e-9);
    const Eigen::Vector2d t_dir = Eigen::Vector2d(3, -4).normalized();
    const Eigen::Vector2d vt = ratio * mu * vn * t_dir;
    const Eigen::Vector3d local(-vn, vt.x(), vt.y());
    f.v = frame * local;
    f.w = Eigen::Vector3d(0.3, -0.2, 1.0);
    const Eigen::Vector3d w0 = f.w;
    const ContactSolveReport report = f.Solve();
    EXPECT_TRUE(report.converged);
    EXPECT_EQ(report.iterations, 1);
    EXPECT_TRUE(report.loaded);
    const Eigen::Vector3d end = frame.transpose() * f.v;
    const Eigen::Vector3d p = f.ws.contacts[0].percussion;
    EXPECT_NEAR(end.x(), 0.0, 1e-12) << ratio;
    EXPECT_NEAR(p.x(), kMass * vn, 1e-9 * kMass) << ratio;
    if (ratio <= 1) {
      EXPECT_LT(end.tail<2>().norm(), 1e-12) << ratio;
    } else {
      const Eigen::Vector2d expected = vt - mu * vn * t_dir;
      EXPECT_LT((end.tail<2>() - expected).norm(), 1e-12) << ratio;
      EXPECT_NEAR(p.tail<2>().norm(), mu * p.x(), 1e-9 * p.x()) << ratio;
    }
    EXPECT_LT((f.w - w0).norm(), 1e-15) << "no lever, no torque";
    // The percussion is remembered in world coordinates for the next step's warm start.
    EXPECT_TRUE(f.ws.last_closed[0]);
    EXPECT_LT((f.ws.last_percussion[0] - frame * p).norm(), 1e-9 * kMass);
  }
}

// Newton's law with epsilon_N = epsilon_T = e at the centre of mass: frictionless, v_N -> -e v_N
// with v_T unchanged; sticking (mu large), the whole contact velocity reverses, v -> -e v.
TEST(SolveContacts, RestitutionReversesTheContactVelocityByE) {
  const Eigen::Matrix3d frame = TiltedFrame();
  for (double e : {0.0, 0.25, 0.8, 1.0}) {
    for (double mu : {0.0, 50.0}) {
      Fixture f;
      f.scene.options.normal_restitution = e;
      f.scene.options.tangential_restitution = e;
      f.Add(Eigen::Vector3d::Zero(), mu, frame);
      const Eigen::Vector3d local(-3.0, 1.0, 0.5);
      f.v = frame * local;
      f.Solve();
      const Eigen::Vector3d end = frame.transpose() * f.v;
      const Eigen::Vector3d expected =
          mu == 0 ? Eigen::Vector3d(3.0 * e, 1.0, 0.5) : Eigen::Vector3d(-e * local);
      EXPECT_LT((end - expected).norm(), 1e-12) << "e " << e << ", mu " << mu;
    }
  }
}

// A contact that separates (v_N >= 0) gets no percussion; a predicted contact (gap g > 0) lets the
// point approach by its gap until the next midpoint: with v_N dt > g it ends at v_N = -g / dt,
// with v_N dt <= g it is left alone.
TEST(SolveContacts, SeparatingAndPredictedContacts) {
  const Eigen::Matrix3d frame = TiltedFrame();
  {
    Fixture f;
    f.Add(Eigen::Vector3d(0.6, 0.4, -0.25), 0.8, frame);
    f.v = frame * Eigen::Vector3d(0.5, 2.0, 0.0);
    f.w = Eigen::Vector3d(0, 0, 0.1);  // the corner still separates
    const Eigen::Vector3d v0 = f.v, w0 = f.w;
    const ContactSolveReport report = f.Solve();
    EXPECT_TRUE(report.converged);
    EXPECT_FALSE(report.loaded);
    EXPECT_EQ(f.v, v0);
    EXPECT_EQ(f.w, w0);
    EXPECT_EQ(f.ws.contacts[0].percussion, Eigen::Vector3d::Zero());
  }
  const double dt = 0.002, gap = 0.004;  // the point may approach at 2 m/s
  for (double vn : {1.0, 2.0, 3.0, 10.0}) {
    Fixture f;
    f.scene.options.dt_s = dt;
    f.Add(Eigen::Vector3d::Zero(), 0.5, frame, gap);
    f.v = frame * Eigen::Vector3d(-vn, 0.1, 0.0);
    const ContactSolveReport report = f.Solve();
    const Eigen::Vector3d end = frame.transpose() * f.v;
    EXPECT_NEAR(end.x(), -std::min(vn, gap / dt), 1e-12) << vn;
    EXPECT_EQ(report.loaded, vn > gap / dt) << vn;
  }
}

// With a lever arm (a bottom corner of a turned box) the percussion acts at the contact point, so
// the angular momentum about that point, L_C = R Theta w - (R b) x m v, is conserved; a sticking
// plastic contact stops the point (v + R (w x b) = 0); a slipping one ends with v_N = 0 at the
// point, |P_T| = mu P_N and P_T opposite to the point's slip. Kinetic energy never increases.
// Tolerances: 1e-9 relative (the exact local solve; the slip branch's Newton iterations stop below
// 1e-13 rad).
TEST(SolveContacts, CornerImpactConservesAngularMomentumAboutTheContactPoint) {
  const Eigen::Matrix3d frame = TiltedFrame();
  for (double mu : {0.1, 0.4, 10.0}) {
    Fixture f;
    f.rotation = (Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()) *
                  Eigen::AngleAxisd(-0.7, Eigen::Vector3d::UnitX()))
                     .toRotationMatrix();
    // The vertex lowest along the contact normal.
    int lowest = 0;
    for (int k = 0; k < static_cast<int>(f.rock.vertices_m.size()); ++k)
      if (frame.col(0).dot(f.rotation * f.rock.vertices_m[k]) <
          frame.col(0).dot(f.rotation * f.rock.vertices_m[lowest]))
        lowest = k;
    const Eigen::Vector3d b = f.rock.vertices_m[lowest];
    f.Add(b, mu, frame);
    f.v = frame * Eigen::Vector3d(-2.5, 1.5, -0.7);
    f.w = Eigen::Vector3d(0.8, -1.2, 2.0);
    const Eigen::Matrix3d inertia = f.rock.inertia_kg_m2.asDiagonal();
    const Eigen::Vector3d rb = f.rotation * b;
    auto momentum = [&] {
      return Eigen::Vector3d(f.rotation * (inertia * f.w) - rb.cross(kMass * f.v));
    };
    auto energy = [&] { return 0.5 * kMass * f.v.squaredNorm() + 0.5 * f.w.dot(inertia * f.w); };
    auto point = [&] {
      return Eigen::Vector3d(frame.transpose() * (f.v + f.rotation * f.w.cross(b)));
    };
    ASSERT_LT(point().x(), 0) << "the corner approaches";
    const Eigen::Vector3d l0 = momentum();
    const double e0 = energy();
    const ContactSolveReport report = f.Solve();
    EXPECT_TRUE(report.converged && report.loaded);
    EXPECT_LT((momentum() - l0).norm(), 1e-9 * l0.norm()) << mu;
    EXPECT_LE(energy(), e0 * (1 + 1e-12)) << mu;
    const Eigen::Vector3d gamma = point();
    const Eigen::Vector3d p = f.ws.contacts[0].percussion;
    EXPECT_NEAR(gamma.x(), 0.0, 1e-9) << mu;
    EXPECT_GT(p.x(), 0) << mu;
    if (p.tail<2>().norm() < mu * p.x() * (1 - 1e-9)) {
      EXPECT_LT(gamma.tail<2>().norm(), 1e-9) << mu << ": inside the cone, the point sticks";
    } else {
      EXPECT_NEAR(p.tail<2>().norm(), mu * p.x(), 1e-9 * p.x()) << mu;
      EXPECT_GT(gamma.tail<2>().norm(), 1e-6) << mu;
      EXPECT_NEAR(p.tail<2>().normalized().dot(gamma.tail<2>().normalized()), -1.0, 1e-9) << mu;
    }
    if (mu == 10.0) {
      EXPECT_LT(gamma.tail<2>().norm(), 1e-9) << "mu 10 sticks";
    }
    if (mu == 0.1) {
      EXPECT_GT(gamma.tail<2>().norm(), 0.1) << "mu 0.1 slips";
    }
  }
}

// The contact-friction reading of the viscous term (h = nu dt m on a contact carrying the whole
// load): at the centre of mass, P_T = -mu P_N t - h v_T' with t the slip direction, so a sliding
// contact ends at v_T' = (|v_T| - mu v_N) / (1 + nu dt) along t; a sticking one still stops.
TEST(SolveContacts, ContactFrictionViscosityDampsTheSlipByOnePlusNuDt) {
  const Eigen::Matrix3d frame = TiltedFrame();
  const double mu = 0.3, nu = 40, dt = 0.01, vn = 1.0;  // nu dt = 0.4: a visible factor
  for (double vt : {0.2, 0.5, 3.0}) {
    Fixture f;
    f.scene.options.viscous = ViscousReading::kContactFriction;
    f.scene.options.dt_s = dt;
    GroundParams ground;
    ground.nu_1_s = nu;
    Contact& c = f.Add(Eigen::Vector3d::Zero(), mu, frame);
    c.ground = f.scene.ground.Set({"viscous", 99, ground});
    f.v = frame * Eigen::Vector3d(-vn, vt, 0);
    f.Solve();
    const Eigen::Vector3d end = frame.transpose() * f.v;
    EXPECT_NEAR(end.x(), 0.0, 1e-12) << vt;
    const double expected = vt <= mu * vn ? 0.0 : (vt - mu * vn) / (1 + nu * dt);
    EXPECT_NEAR(end.y(), expected, 1e-12) << vt;
    EXPECT_NEAR(end.z(), 0.0, 1e-12) << vt;
  }
}

// EffectiveInertia: where the step folds a drag into the velocity update, a percussion P changes
// v by P / mass_kg of that larger mass: a plastic sticking contact at the centre of mass still
// stops the rock, with P = -(effective mass) v.
TEST(SolveContacts, EffectiveMassScalesThePercussion) {
  const Eigen::Matrix3d frame = TiltedFrame();
  Fixture f;
  f.Add(Eigen::Vector3d::Zero(), 5.0, frame);
  f.v = frame * Eigen::Vector3d(-1.0, 0.5, 0.25);
  const Eigen::Vector3d local = frame.transpose() * f.v;
  f.Solve(3 * kMass);
  EXPECT_LT(f.v.norm(), 1e-12);
  EXPECT_LT((f.ws.contacts[0].percussion + 3 * kMass * local).norm(), 1e-9 * kMass);
}

// A single contact is solved exactly whatever the warm start: the previous step's percussion of
// its vertex (any value, made admissible) gives the same end velocities as a cold start.
TEST(SolveContacts, SingleContactResultDoesNotDependOnTheWarmStart) {
  const Eigen::Matrix3d frame = TiltedFrame();
  auto run = [&](const Eigen::Vector3d& warm) {
    Fixture f;
    f.Add(Eigen::Vector3d(0.6, -0.4, -0.25), 0.5, frame);
    f.ws.last_closed[0] = 1;
    f.ws.last_percussion[0] = warm;
    f.v = frame * Eigen::Vector3d(-2.0, 0.7, 0.2);
    f.w = Eigen::Vector3d(0.4, 0.1, -0.5);
    f.Solve();
    return std::pair{f.v, f.w};
  };
  const auto [v0, w0] = run(Eigen::Vector3d::Zero());
  for (const Eigen::Vector3d& warm :
       {Eigen::Vector3d(0, 0, 3000), Eigen::Vector3d(500, -200, -1000),
        Eigen::Vector3d(-1e4, 1e4, 1e4)}) {
    const auto [v, w] = run(warm);
    EXPECT_LT((v - v0).norm(), 1e-9) << warm.transpose();
    EXPECT_LT((w - w0).norm(), 1e-9) << warm.transpose();
  }
}

// Two contacts at the midpoints of the bottom edges of the box, x = +-0.6 m, falling flat at
// 1.5 m/s without rotation: the plastic solution stops the box (v = 0, w = 0) with P_N = m v / 2
// at each; Gauss-Seidel needs several sweeps, the block method one sweep and one block solve.
TEST(SolveContacts, TwoSymmetricContactsStopAFlatFallingBox) {
  for (ContactSolveMethod method : {ContactSolveMethod::kGaussSeidel, ContactSolveMethod::kBlock}) {
    Fixture f;
    f.scene.options.contact_solve = method;
    f.scene.options.tolerance_m_s = 1e-9;
    Eigen::Matrix3d up;  // n = z, t1 = x, t2 = y
    up << Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY();
    f.Add(Eigen::Vector3d(0.6, 0, -0.25), 0.7, up);
    f.Add(Eigen::Vector3d(-0.6, 0, -0.25), 0.7, up);
    f.v = Eigen::Vector3d(0, 0, -1.5);
    const ContactSolveReport report = f.Solve();
    EXPECT_TRUE(report.converged) << ToString(method);
    EXPECT_GT(report.iterations, 1) << ToString(method);
    EXPECT_LT(f.v.norm() + 0.75 * f.w.norm(), 1e-7) << ToString(method);
    for (const Contact& c : f.ws.contacts)
      EXPECT_NEAR(c.percussion.x(), kMass * 1.5 / 2, 1e-6 * kMass) << ToString(method);
  }
}

}  // namespace
}  // namespace talus
