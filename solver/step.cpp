#include "solver/step.hpp"

#include <cmath>

#include "solver/contact_detection.hpp"
#include "solver/contact_solver.hpp"
#include "solver/kinematics.hpp"

namespace talus {
namespace {

// Scar: grows with the speed while a contact carries load, decays as exp(-beta dt) otherwise.
void UpdateScar(const Scene& scene, const StepReport& report, const StepWorkspace& workspace,
                RockState& state) {
  const double dt = scene.options.dt_s;
  if (report.loaded) {
    state.scar_m += dt * state.velocity_m_s.norm();
    for (const Contact& c : workspace.contacts)
      if (c.percussion.x() > 0) state.scar_ground = c.ground;
  } else if (state.scar_m > 0) {
    const int ground = state.scar_ground >= 0 ? state.scar_ground : scene.terrain.default_ground();
    state.scar_m *= std::exp(-scene.ground.params(ground).beta_1_s * dt);
  }
}

// End velocity under gravity alone.
Eigen::Vector3d FreeVelocity(const SolverOptions& opt, const Eigen::Vector3d& v_begin) {
  Eigen::Vector3d velocity = v_begin;
  velocity.z() -= opt.dt_s * opt.gravity_m_s2;
  return velocity;
}

// End point (drift the second half with the end velocities), time and scar.
void EndStep(const Scene& scene, const StepReport& report, const StepWorkspace& workspace,
             RockState& state) {
  Drift(state, 0.5 * scene.options.dt_s);
  state.time_s += scene.options.dt_s;
  UpdateScar(scene, report, workspace, state);
}

// Centre-of-mass reading of the viscous term: implicit drag -m nu v_E with the mean nu of the
// step's contacts, m (1 + nu dt) v_E = m v_free + sum P. Divides the free velocity by 1 + nu dt
// and multiplies the effective translational mass by it.
void CentreOfMassDrag(const Scene& scene, const StepWorkspace& workspace,
                      Eigen::Vector3d& velocity, EffectiveInertia& inertia) {
  double nu = 0;
  for (const Contact& c : workspace.contacts) nu += scene.ground.params(c.ground).nu_1_s;
  nu /= static_cast<double>(workspace.contacts.size());
  const double drag_factor = 1.0 + nu * scene.options.dt_s;
  velocity /= drag_factor;
  inertia.mass_kg *= drag_factor;
}

// phi(x) = (1 - exp(-x)) / x, phi(0) = 1.
double Phi(double x) { return x > 0 ? -std::expm1(-x) / x : 1.0; }

// Drag layer (docs/model.md, "The drag layer"): when the centre of mass at the midpoint is at most
// the layer's height above the terrain under it, integrates m dv/dt = -m c_t v + F exactly for F
// constant over the step: v_E = exp(-c_t dt) v_B + phi(c_t dt) dt F / m, and likewise Omega with
// c_r after the free rotation. Contact percussions enter as F dt, so the effective mass and inertia
// grow by 1 / phi. Both factors are in (0, 1]: the layer only takes energy.
void DragLayer(const Scene& scene, const Eigen::Vector3d& centre, const Eigen::Vector3d& v_begin,
               Eigen::Vector3d& velocity, Eigen::Vector3d& omega, EffectiveInertia& inertia) {
  double height = 0;
  if (!scene.terrain.Height(centre.x(), centre.y(), &height)) return;
  const GroundParams& g = scene.ground.params(scene.terrain.GroundAt(centre.x(), centre.y()));
  if (!g.HasDragLayer() || centre.z() - height > g.drag_height_m) return;
  const double dt = scene.options.dt_s;
  const double x_t = g.drag_translational_1_s * dt;
  const double x_r = g.drag_rotational_1_s * dt;
  // velocity holds v_B + dt F / m (gravity): replace by exp(-x) v_B + phi(x) dt F / m.
  velocity = std::exp(-x_t) * v_begin + Phi(x_t) * (velocity - v_begin);
  omega *= std::exp(-x_r);
  inertia.mass_kg /= Phi(x_t);
  inertia.inertia_scale /= Phi(x_r);
}

}  // namespace

StepReport Step(const Scene& scene, const RockShape& rock, RockState& state,
                StepWorkspace& workspace, StageTimes* times) {
  const SolverOptions& opt = scene.options;
  const double dt = opt.dt_s;
  const RockState begin = state;
  StepReport report;
  StageClock clock(times);

  // 1. Midpoint: drift half a step with the begin velocities.
  Drift(state, 0.5 * dt);
  clock.Lap(&StageTimes::midpoint_s);

  // 2. Free rotation by the implicit midpoint rule.
  Eigen::Vector3d omega = FreeRotation(rock.inertia_kg_m2, begin.angular_velocity_rad_s, dt);
  clock.Lap(&StageTimes::free_rotation_s);

  // 3. Free end velocities: gravity, and the drag layer where the centre of mass is inside one.
  Eigen::Vector3d velocity = FreeVelocity(opt, begin.velocity_m_s);
  EffectiveInertia inertia{rock.mass_kg, 1.0};
  if (scene.ground.AnyDragLayer())
    DragLayer(scene, state.position_m, begin.velocity_m_s, velocity, omega, inertia);

  // 4. Contact set at the midpoint: closed contacts and, with a plastic normal law, the vertices
  // that the free motion (no contacts) would carry deeper than the penetration tolerance below the
  // terrain by the next midpoint.
  const double allowed_depth = opt.penetration_tolerance * rock.thickness_m;
  const Eigen::Matrix3d rotation = state.orientation.toRotationMatrix();
  const DetectResult detected = DetectContacts(scene, rock, state, rotation, velocity, omega,
                                               PredictionHorizon(opt), allowed_depth, workspace);
  if (detected == DetectResult::kOutsideDomain) {
    state = begin;
    report.outside_domain = true;
    return report;
  }
  report.clear = detected == DetectResult::kClear;
  clock.Lap(&StageTimes::contacts_s);

  // 5. Velocity update: the viscous term (centre-of-mass reading: implicit drag m (1 + nu dt) v_E
  // here; contact-friction reading: inside the contact law), then percussions.
  if (workspace.contacts.empty()) {
    workspace.ForgetPercussions();
  } else {
    if (opt.viscous == ViscousReading::kCentreOfMass)
      CentreOfMassDrag(scene, workspace, velocity, inertia);
    const ContactSolveReport solve =
        SolveContacts(scene, rock, rotation, inertia, begin.velocity_m_s,
                      begin.angular_velocity_rad_s, velocity, omega, workspace);
    for (const Contact& c : workspace.contacts)
      report.contacts += c.gap_m == 0 || c.percussion.x() > 0;
    report.iterations = solve.iterations;
    report.converged = solve.converged;
    report.loaded = solve.loaded;
  }
  state.velocity_m_s = velocity;
  state.angular_velocity_rad_s = omega;
  clock.Lap(&StageTimes::solve_s);

  // 6. End point: drift the second half with the end velocities; 7. scar evolution.
  EndStep(scene, report, workspace, state);
  clock.Lap(&StageTimes::end_s);
  if (times) ++times->steps;
  return report;
}

StepReport FlightStep(const Scene& scene, const RockShape& rock, RockState& state,
                      StepWorkspace& workspace, StageTimes* times) {
  StepReport report;
  report.clear = true;
  StageClock clock(times);
  Drift(state, 0.5 * scene.options.dt_s);
  clock.Lap(&StageTimes::midpoint_s);
  state.angular_velocity_rad_s =
      FreeRotation(rock.inertia_kg_m2, state.angular_velocity_rad_s, scene.options.dt_s);
  clock.Lap(&StageTimes::free_rotation_s);
  state.velocity_m_s = FreeVelocity(scene.options, state.velocity_m_s);
  workspace.contacts.clear();
  workspace.ForgetPercussions();
  EndStep(scene, report, workspace, state);
  clock.Lap(&StageTimes::end_s);
  if (times) ++times->steps;
  return report;
}

}  // namespace talus
