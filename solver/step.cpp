#include "solver/step.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>

#include "solver/contact_detection.hpp"
#include "solver/contact_solver.hpp"
#include "solver/kinematics.hpp"
#include "solver/soil.hpp"

namespace talus {
namespace {

// Scar: grows with the speed while a contact carries load, decays as exp(-beta dt) otherwise.
// The decay's factor is kept with its beta and dt, which a flight repeats in every step.
void UpdateScar(const Scene& scene, double dt, const StepReport& report, StepWorkspace& workspace,
                RockState& state) {
  if (report.loaded) {
    state.scar_m += dt * state.velocity_m_s.norm();
    for (const Contact& c : workspace.contacts)
      if (c.percussion.x() > 0) state.scar_ground = c.ground;
  } else if (state.scar_m > 0) {
    const int ground = state.scar_ground >= 0 ? state.scar_ground : scene.terrain.default_ground();
    const double beta = scene.ground.params(ground).beta_1_s;
    StepWorkspace::ScarDecay& decay = workspace.scar_decay;
    if (beta != decay.beta_1_s || dt != decay.dt_s)  // NaN until set: taken the first time
      decay = {beta, dt, std::exp(-beta * dt)};
    state.scar_m *= decay.factor;
  }
}

// End velocity under gravity alone after dt.
Eigen::Vector3d FreeVelocity(const SolverOptions& opt, double dt, const Eigen::Vector3d& v_begin) {
  Eigen::Vector3d velocity = v_begin;
  velocity.z() -= dt * opt.gravity_m_s2;
  return velocity;
}

// End point (drift the second half with the end velocities), time and scar.
void EndStep(const Scene& scene, double dt, const StepReport& report, StepWorkspace& workspace,
             RockState& state) {
  Drift(state, 0.5 * dt, &workspace.drift_turn);
  state.time_s += dt;
  UpdateScar(scene, dt, report, workspace, state);
}

// Centre-of-mass reading of the viscous term: implicit drag -m nu v_E with the mean nu of the
// step's contacts, m (1 + nu dt) v_E = m v_free + sum P. Divides the free velocity by 1 + nu dt
// and multiplies the effective translational mass by it.
void CentreOfMassDrag(const Scene& scene, double dt, const StepWorkspace& workspace,
                      Eigen::Vector3d& velocity, EffectiveInertia& inertia) {
  double nu = 0;
  for (const Contact& c : workspace.contacts) nu += scene.ground.params(c.ground).nu_1_s;
  nu /= static_cast<double>(workspace.contacts.size());
  const double drag_factor = 1.0 + nu * dt;
  velocity /= drag_factor;
  inertia.mass_kg *= drag_factor;
}

// phi(x) = (1 - exp(-x)) / x, phi(0) = 1.
double Phi(double x) { return x > 0 ? -std::expm1(-x) / x : 1.0; }

// Drag layer (docs/model.md, "The drag layer"): when the centre of mass at the midpoint is at most
// the layer's height above the terrain under it, integrates m dv/dt = -m c_t v + F exactly for F
// constant over the step: v_E = exp(-c_t dt) v_B + phi(c_t dt) dt F / m, and likewise Omega with
// c_r after the free rotation. Contact percussions enter as F dt, so the effective mass and inertia
// grow by 1 / phi. Both factors are in (0, 1]: the layer only takes energy. The forest's drag
// (solver/forest.hpp, ForestDrag) adds its rate, from the step's beginning, to both c_t and c_r.
void DragLayer(const Scene& scene, double dt, const RockShape& rock, const Eigen::Vector3d& centre,
               const RockState& begin, Eigen::Vector3d& velocity, Eigen::Vector3d& omega,
               EffectiveInertia& inertia) {
  double height = 0;
  if (!scene.terrain.Height(centre.x(), centre.y(), &height)) return;
  const GroundParams& g = scene.ground.params(scene.terrain.GroundAt(centre.x(), centre.y()));
  const bool ground_layer = g.HasDragLayer() && centre.z() - height <= g.drag_height_m;
  double c_t = ground_layer ? g.drag_translational_1_s : 0.0;
  double c_r = ground_layer ? g.drag_rotational_1_s : 0.0;
  if (!scene.forest_drag.empty()) {
    const double c =
        ForestDragRate_1_s(scene.forest_drag, rock, begin, centre, centre.z() - height);
    c_t += c;
    c_r += c;
  }
  if (!ground_layer && c_t == 0 && c_r == 0) return;
  const Eigen::Vector3d& v_begin = begin.velocity_m_s;
  const double x_t = c_t * dt;
  const double x_r = c_r * dt;
  // velocity holds v_B + dt F / m (gravity): replace by exp(-x) v_B + phi(x) dt F / m.
  velocity = std::exp(-x_t) * v_begin + Phi(x_t) * (velocity - v_begin);
  omega *= std::exp(-x_r);
  inertia.mass_kg /= Phi(x_t);
  inertia.inertia_scale /= Phi(x_r);
}

// Scar drag of the scarring soil (Lu et al. 2019, eqs. 9 and 12; docs/model.md, "The scarring
// soil"): F = (C_f + C_s) rho / 2 A zeta'^2 against the velocity v of the point where it acts,
// zeta' the rate of penetration -- of its depth below the surface measured vertically, (v . n) /
// n_z for the terrain's tangent plane with normal n under the centre of mass: zero for motion
// parallel to the surface -- and A the frontal area of the hull's part below that plane, projected
// normal to v. Implicit in v with zeta'^2 / |v| from the step's beginning: F = -k (zeta_B'^2 /
// |v_B|) v_E.
// - centre of mass (the paper): m (1 + dt k zeta'^2 / (m |v|)) v_E = m v_free + sum P, folded into
//   the contact solve as CentreOfMassDrag folds nu;
// - submerged centroid: the percussion P = -h v_c,E (h = dt k zeta_c'^2 / |v_c|, kg) at the part's
//   centroid c, v_c,E = v_c,free + K P with K the point's inverse mass matrix, solved before the
//   contacts.
// Both only take energy: P . v_c,E <= 0. Reports the penetration (m) along the plane's normal.
void SoilDrag(const Scene& scene, double dt, const RockShape& rock, const RockState& mid,
              const Eigen::Matrix3d& rotation, const RockState& begin, Eigen::Vector3d& velocity,
              Eigen::Vector3d& omega, EffectiveInertia& inertia, StepWorkspace& workspace,
              StepReport& report) {
  TerrainSample under;
  if (!scene.terrain.Sample(mid.position_m.x(), mid.position_m.y(), &under)) return;
  const Eigen::Vector3d plane_point(0, 0, under.height_m - mid.position_m.z());
  SubmergedPart& part = workspace.submerged;
  const Eigen::Vector3d along(begin.velocity_m_s.x(), begin.velocity_m_s.y(), 0);
  ClipBelowPlane(rock, rotation, plane_point, under.normal, &part, along);
  report.soil_penetration_m = part.depth_m;
  if (part.empty()) return;
  report.soil_rear_m = mid.position_m + part.rear_m;
  report.soil_front_m = mid.position_m + part.front_m;
  const double k = scene.ground.params(workspace.soil.ground).DragFactor_kg_m3();
  if (scene.options.soil_drag == SoilDragPoint::kCentreOfMass) {
    const double speed = begin.velocity_m_s.norm();
    if (speed == 0) return;
    const double rate = begin.velocity_m_s.dot(under.normal) / under.normal.z();
    const double h = dt * k * part.FrontalArea(begin.velocity_m_s / speed) * rate * rate / speed;
    velocity *= inertia.mass_kg / (inertia.mass_kg + h);
    inertia.mass_kg += h;
    return;
  }
  const Eigen::Vector3d& a = part.centroid_m;
  const Eigen::Vector3d point_begin =
      begin.velocity_m_s + (begin.orientation * begin.angular_velocity_rad_s).cross(a);
  const double speed = point_begin.norm();
  if (speed == 0) return;
  const double rate = point_begin.dot(under.normal) / under.normal.z();
  const double h = dt * k * part.FrontalArea(point_begin / speed) * rate * rate / speed;
  // K = I / m - [a]x R Theta^-1 R' [a]x, the velocity change of point c per unit percussion there.
  const Eigen::Vector3d inv_inertia = rock.inertia_kg_m2.cwiseInverse() / inertia.inertia_scale;
  Eigen::Matrix3d cross_a;
  cross_a << 0, -a.z(), a.y(), a.z(), 0, -a.x(), -a.y(), a.x(), 0;
  const Eigen::Matrix3d rotated = rotation * inv_inertia.asDiagonal() * rotation.transpose();
  const Eigen::Matrix3d mobility =
      Eigen::Matrix3d::Identity() / inertia.mass_kg - cross_a * rotated * cross_a;
  const Eigen::Vector3d point_free = velocity + (rotation * omega).cross(a);
  const Eigen::Vector3d percussion =
      -h * (Eigen::Matrix3d::Identity() + h * mobility).partialPivLu().solve(point_free);
  velocity += percussion / inertia.mass_kg;
  omega += inv_inertia.cwiseProduct(rotation.transpose() * a.cross(percussion));
}

// Whether a step is an impact that sub-steps should take (docs/model.md, "Impact sub-steps"): its
// contact set holds a predicted contact (a vertex open at the midpoint that closes before the next
// one), or a vertex that was within the allowed depth at the step's begin is deeper than that at
// the midpoint. The second is the impact the step before could not stop because it was itself
// split: its sub-steps predict over their own short horizons, so a vertex arriving in the first
// half of this step was seen by none of them, and a predicted contact's gap law in the last
// sub-step lets its vertex approach at up to its gap over a sub-step, k times faster than over a
// step. Without this check a slab landing at 7.7 m/s at dt 2 ms sank 4.5 mm (4.5 % of its
// thickness) and a 0.1 m cube at dt 10 ms 3.4 mm. Soil contacts sink by design and are left out.
// With SubstepImpacts::kAll, also a vertex closed at the midpoint that was no contact in the step
// before: an impact however slowly its vertex arrives (docs/model.md, "Arrivals as impacts").
bool NeedsSubsteps(const Scene& scene, const RockShape& rock, const RockState& begin,
                   const RockState& mid, const Eigen::Matrix3d& rotation, double allowed_depth,
                   const StepWorkspace& workspace) {
  const bool every_impact = scene.options.substep_impacts == SubstepImpacts::kAll;
  for (const Contact& c : workspace.contacts) {
    if (c.held) continue;
    if (c.gap_m > 0) return true;
    if (c.corner || scene.ground.params(c.ground).IsSoil()) continue;
    if (every_impact && !workspace.last_closed[c.vertex]) return true;  // a new contact
    const Eigen::Vector3d& b = rock.vertices_m[c.vertex];
    const Eigen::Vector3d x = mid.position_m + rotation * b;
    double height;
    if (!scene.terrain.Height(x.x(), x.y(), &height)) continue;
    if ((height - x.z()) * c.directions(2, 0) <= allowed_depth) continue;
    const Eigen::Vector3d x_begin = begin.position_m + begin.orientation * b;
    double height_begin;
    if (scene.terrain.Height(x_begin.x(), x_begin.y(), &height_begin) &&
        (height_begin - x_begin.z()) * c.directions(2, 0) <= allowed_depth)
      return true;
  }
  return false;
}

// One step of length dt (docs/model.md). With may_split, a step whose contact set holds a predicted
// contact (open at the midpoint, closing before the step ends) stops right after contact detection,
// with the state and the workspace's warm start untouched, and reports split: the caller redoes it
// as sub-steps.
StepReport StepOnce(const Scene& scene, const RockShape& rock, double dt, bool may_split,
                    RockState& state, StepWorkspace& workspace, StageTimes* times) {
  const SolverOptions& opt = scene.options;
  const RockState begin = state;
  StepReport report;
  StageClock clock(times);

  // 1. Midpoint: drift half a step with the begin velocities.
  Drift(state, 0.5 * dt, &workspace.drift_turn);
  clock.Lap(&StageTimes::midpoint_s);

  // 2. Free rotation by the implicit midpoint rule.
  Eigen::Vector3d omega = FreeRotation(rock.inertia_kg_m2, begin.angular_velocity_rad_s, dt);
  clock.Lap(&StageTimes::free_rotation_s);

  // 3. Free end velocities: gravity, and the drag layer where the centre of mass is inside one.
  Eigen::Vector3d velocity = FreeVelocity(opt, dt, begin.velocity_m_s);
  EffectiveInertia inertia{rock.mass_kg, 1.0};
  if (workspace.scene_has_drag)
    DragLayer(scene, dt, rock, state.position_m, begin, velocity, omega, inertia);

  // 4. Contact set at the midpoint: closed contacts and the vertices that the free motion (no
  // contacts) would carry deeper than the penetration tolerance below the terrain by the next
  // midpoint (the prediction's horizon is the step's length).
  const double allowed_depth = opt.penetration_tolerance * rock.thickness_m;
  const Eigen::Matrix3d rotation = state.orientation.toRotationMatrix();
  const DetectResult detected =
      DetectContacts(scene, rock, state, rotation, velocity, omega, dt, allowed_depth, workspace);
  if (detected == DetectResult::kOutsideDomain) {
    state = begin;
    report.outside_domain = true;
    return report;
  }
  if (may_split && NeedsSubsteps(scene, rock, begin, state, rotation, allowed_depth, workspace)) {
    state = begin;
    report.split = true;
    return report;
  }
  report.clear = detected == DetectResult::kClear;
  state.soil_ground = workspace.soil.ground;
  state.soil_depth_m = workspace.soil.depth_m;
  report.in_soil = workspace.soil.submerged;
  if (workspace.soil.submerged)
    SoilDrag(scene, dt, rock, state, rotation, begin, velocity, omega, inertia, workspace, report);
  clock.Lap(&StageTimes::contacts_s);

  // 5. Velocity update: the viscous term (centre-of-mass reading: implicit drag m (1 + nu dt) v_E
  // here; contact-friction reading: inside the contact law), then percussions.
  if (workspace.contacts.empty()) {
    workspace.ForgetPercussions();
  } else {
    if (opt.viscous == ViscousReading::kCentreOfMass)
      CentreOfMassDrag(scene, dt, workspace, velocity, inertia);
    const ContactSolveReport solve =
        SolveContacts(scene, rock, dt, rotation, inertia, begin.velocity_m_s,
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
  EndStep(scene, dt, report, workspace, state);
  clock.Lap(&StageTimes::end_s);
  return report;
}

}  // namespace

StepReport Step(const Scene& scene, const RockShape& rock, RockState& state,
                StepWorkspace& workspace, StageTimes* times) {
  const SolverOptions& opt = scene.options;
  // Newton's law (restitution > 0) takes the begin velocities of the step it acts in: its steps
  // are not split (SolverOptions::impact_substeps).
  const int substeps = opt.normal_restitution > 0 ? 1 : opt.impact_substeps;
  StepReport report = StepOnce(scene, rock, opt.dt_s, substeps > 1, state, workspace, times);
  if (times && !report.outside_domain) ++times->steps;  // one step, whatever its parts
  if (!report.split) return report;
  // A predicted contact: the step again as sub-steps of dt / substeps, so that the contact's
  // percussion acts near the instant the vertex arrives rather than up to a whole step early
  // (docs/model.md, "Impact sub-steps"). One report for the whole step: the most contacts and the
  // sum of sweeps of any sub-step; loaded, in soil and unconverged if any sub-step was; the
  // deepest soil penetration, and the scar from the first in-soil sub-step's rear to the last
  // one's front.
  const RockState begin = state;
  const double dt = opt.dt_s / substeps;
  StepReport merged;
  bool soil_seen = false;
  for (int k = 0; k < substeps; ++k) {
    StepReport sub = StepOnce(scene, rock, dt, false, state, workspace, times);
    if (sub.outside_domain) {
      state = begin;
      return sub;
    }
    merged.contacts = std::max(merged.contacts, sub.contacts);
    merged.iterations += sub.iterations;
    merged.converged = merged.converged && sub.converged;
    merged.loaded = merged.loaded || sub.loaded;
    merged.in_soil = merged.in_soil || sub.in_soil;
    merged.soil_penetration_m = std::max(merged.soil_penetration_m, sub.soil_penetration_m);
    // The scar this step cut: from the first sub-step's rear to the last one's front.
    if (sub.in_soil) {
      if (!soil_seen) merged.soil_rear_m = sub.soil_rear_m;
      merged.soil_front_m = sub.soil_front_m;
      soil_seen = true;
    }
  }
  merged.substeps = substeps;
  state.time_s = begin.time_s + opt.dt_s;  // the sub-steps' sum, without its round-off
  return merged;
}

StepReport FlightStep(const Scene& scene, const RockShape& rock, RockState& state,
                      StepWorkspace& workspace, StageTimes* times) {
  StepReport report;
  report.clear = true;
  StageClock clock(times);
  Drift(state, 0.5 * scene.options.dt_s, &workspace.drift_turn);
  clock.Lap(&StageTimes::midpoint_s);
  state.angular_velocity_rad_s =
      FreeRotation(rock.inertia_kg_m2, state.angular_velocity_rad_s, scene.options.dt_s);
  clock.Lap(&StageTimes::free_rotation_s);
  state.velocity_m_s = FreeVelocity(scene.options, scene.options.dt_s, state.velocity_m_s);
  workspace.contacts.clear();
  workspace.ForgetPercussions();
  state.soil_ground = -1;
  state.soil_depth_m = 0;
  EndStep(scene, scene.options.dt_s, report, workspace, state);
  clock.Lap(&StageTimes::end_s);
  if (times) ++times->steps;
  return report;
}

}  // namespace talus
