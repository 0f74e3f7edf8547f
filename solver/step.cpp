#include "solver/step.hpp"

#include <chrono>
#include <cmath>

#include "solver/contact_detection.hpp"
#include "solver/contact_solver.hpp"
#include "solver/kinematics.hpp"

namespace talus {
namespace {

// Accumulates the time since the last lap into a stage's counter; free when not profiling.
class StageClock {
 public:
  explicit StageClock(StageTimes* times) : times_(times) {
    if (times_) last_ = std::chrono::steady_clock::now();
  }
  void Lap(double StageTimes::*stage) {
    if (!times_) return;
    const auto now = std::chrono::steady_clock::now();
    times_->*stage += std::chrono::duration<double>(now - last_).count();
    last_ = now;
  }

 private:
  StageTimes* times_;
  std::chrono::steady_clock::time_point last_;
};

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

// Centre-of-mass reading of the viscous term: implicit drag -m nu v_E with the mean nu of the
// step's contacts, m (1 + nu dt) v_E = m v_free + sum P. Divides the free velocity by 1 + nu dt
// and returns the effective translational mass m (1 + nu dt) for the contact solve.
double CentreOfMassDrag(const Scene& scene, const RockShape& rock, const StepWorkspace& workspace,
                        Eigen::Vector3d& velocity) {
  double nu = 0;
  for (const Contact& c : workspace.contacts) nu += scene.ground.params(c.ground).nu_1_s;
  nu /= static_cast<double>(workspace.contacts.size());
  const double drag_factor = 1.0 + nu * scene.options.dt_s;
  velocity /= drag_factor;
  return rock.mass_kg * drag_factor;
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

  // 3. Contact set at the midpoint: closed contacts and, with a plastic normal law, the vertices
  // that the free motion (gravity, no contacts) would carry deeper than the penetration tolerance
  // below the terrain by the next midpoint.
  Eigen::Vector3d velocity = begin.velocity_m_s;
  velocity.z() -= dt * opt.gravity_m_s2;
  const double horizon = opt.normal_restitution == 0 ? dt : 0.0;
  const double allowed_depth = opt.penetration_tolerance * rock.thickness_m;
  const Eigen::Matrix3d rotation = state.orientation.toRotationMatrix();
  if (DetectContacts(scene, rock, state, rotation, velocity, omega, horizon, allowed_depth,
                     workspace) == DetectResult::kOutsideDomain) {
    state = begin;
    report.outside_domain = true;
    return report;
  }
  clock.Lap(&StageTimes::contacts_s);

  // 4. Velocity update: gravity, the viscous term (centre-of-mass reading: implicit drag
  // m (1 + nu dt) v_E here; contact-friction reading: inside the contact law), then percussions.
  if (workspace.contacts.empty()) {
    workspace.ForgetPercussions();
  } else {
    const double mass_eff = opt.viscous == ViscousReading::kCentreOfMass
                                ? CentreOfMassDrag(scene, rock, workspace, velocity)
                                : rock.mass_kg;
    const ContactSolveReport solve =
        SolveContacts(scene, rock, rotation, mass_eff, begin.velocity_m_s,
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

  // 5. End point: drift the second half with the end velocities.
  Drift(state, 0.5 * dt);
  state.time_s += dt;

  // 6. Scar evolution.
  UpdateScar(scene, report, workspace, state);
  clock.Lap(&StageTimes::end_s);
  if (times) ++times->steps;
  return report;
}

}  // namespace talus
