#include "solver/contact_solver.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>

#include "solver/contact_block.hpp"

namespace talus {
namespace {

// The slip Newton's stopping rule (wave 1): its last turn of d, rad.
constexpr double kConvergedTurn_rad = 1e-7;

// Slip branch of one contact: P = P_N (1, mu d) with d a unit vector opposite to the tangential
// velocity of gamma = xi0 + G P, and gamma_N = 0. Newton's method on the angle of d for
// F = d x gamma_T = 0 (analytic derivative; d is turned without trigonometric calls), started
// opposite to the tangential velocity that a frictionless impact would leave.
//
// SlipControl: wave 1 (the default) starts as above and stops when the step is below 1e-7 rad;
// the block method (ContactSolveMethod::kBlock) starts from `start` when given (the slip direction
// of the contact's previous iterate, warm-started from the previous step) and stops as soon as the
// slip velocity normal to d, |d x gamma_T| (m/s), is below f_tolerance.
struct SlipControl {
  const Eigen::Vector2d* start = nullptr;
  double f_tolerance = 0;  // 0: wave 1's stopping rule
};
bool SolveSlip(const Eigen::Matrix3d& g, const Eigen::Vector3d& xi0, double mu, Eigen::Vector3d* p,
               const SlipControl& control = {}) {
  const double a = g(0, 0);
  const Eigen::Vector2d b = g.block<2, 1>(1, 0);
  const Eigen::Matrix2d c = g.block<2, 2>(1, 1);
  auto cross = [](const Eigen::Vector2d& u, const Eigen::Vector2d& v) {
    return u.x() * v.y() - u.y() * v.x();
  };
  Eigen::Vector2d d =
      control.start ? *control.start : Eigen::Vector2d(-(xi0.tail<2>() - (xi0.x() / a) * b));
  if (d.squaredNorm() == 0) return false;
  d.normalize();
  double normal = 0, denominator = 0;
  Eigen::Vector2d gamma_t;
  for (int iter = 0; iter < 40; ++iter) {
    const Eigen::Vector2d d_perp(-d.y(), d.x());  // d rotated by +90 degrees: dd/dphi
    denominator = a + mu * b.dot(d);
    const double inv_denominator = 1.0 / denominator;
    normal = -xi0.x() * inv_denominator;
    const Eigen::Vector2d lever = b + mu * (c * d);
    gamma_t = xi0.tail<2>() + normal * lever;
    const double f = cross(d, gamma_t);
    if (control.f_tolerance > 0 && std::abs(f) <= control.f_tolerance) break;
    const double normal_slope = -normal * mu * b.dot(d_perp) * inv_denominator;
    const Eigen::Vector2d gamma_slope = normal_slope * lever + normal * mu * (c * d_perp);
    const double f_slope = -d.dot(gamma_t) + cross(d, gamma_slope);
    if (!(f_slope != 0) || !std::isfinite(f_slope)) return false;
    const double step = std::clamp(-f / f_slope, -0.5, 0.5);
    // Turns d by atan(step); |d + step d_perp| = sqrt(1 + step^2) as d_perp is d turned.
    d = (d + step * d_perp) * (1.0 / std::sqrt(1.0 + step * step));
    // Newton's quadratic convergence leaves, after a turn below 1e-7 rad, an error of the order of
    // its square: the percussions agree with those of a stop at a turn below 1e-13 rad (one more
    // iteration) to 9e-13 relative over the 4e5 slip problems of 50 ramp rocks and to 1.3e-11
    // over 2e5 random ones (bench/README.md, "The slip Newton's stopping rule"). The check below
    // still refuses a d whose slip is off its normal.
    if (std::abs(step) < kConvergedTurn_rad) break;
  }
  denominator = a + mu * b.dot(d);
  normal = -xi0.x() / denominator;
  gamma_t = xi0.tail<2>() + normal * (b + mu * (c * d));
  // Admissible only with a compressive normal percussion and d opposite to the slip velocity.
  if (!(denominator > 0 && normal >= 0 && d.dot(gamma_t) <= 0)) return false;
  if (std::abs(cross(d, gamma_t)) >
      (control.f_tolerance > 0 ? control.f_tolerance : 1e-9 * (gamma_t.norm() + 1e-12)))
    return false;
  *p = Eigen::Vector3d(normal, mu * normal * d.x(), mu * normal * d.y());
  return true;
}

// Exact solution of one contact's laws with all other percussions held fixed: gamma = xi0 + G P
// with Signorini in the normal and Coulomb in the tangent plane (g = G, g_inverse = G^-1). Tries
// separation, then sticking, then slipping. Returns false when the slip iteration does not
// converge.
bool SolveLocal(const Eigen::Matrix3d& g, const Eigen::Matrix3d& g_inverse, double mu,
                const Eigen::Vector3d& xi0, Eigen::Vector3d* p, const SlipControl& control) {
  if (xi0.x() >= 0) {
    p->setZero();
    return true;
  }
  const Eigen::Vector3d stick = -(g_inverse * xi0);
  if (stick.x() >= 0 && stick.tail<2>().norm() <= mu * stick.x()) {
    *p = stick;
    return true;
  }
  if (mu == 0) {
    *p = Eigen::Vector3d(-xi0.x() / g(0, 0), 0, 0);
    return true;
  }
  return SolveSlip(g, xi0, mu, p, control);
}

// Fallback: proximal-point iterations on the contact's own 3 x 3 problem.
Eigen::Vector3d ProxLocal(const Eigen::Matrix3d& g, double mu, double r_normal, double r_tangent,
                          const Eigen::Vector3d& xi0, Eigen::Vector3d p, double tolerance) {
  for (int iter = 0; iter < 1000; ++iter) {
    const Eigen::Vector3d xi = xi0 + g * p;
    Eigen::Vector3d next;
    next.x() = std::max(0.0, p.x() - r_normal * xi.x());
    next.tail<2>() = ProjectDisk(p.tail<2>() - r_tangent * xi.tail<2>(), mu * next.x());
    const double change = (g * (next - p)).norm();
    p = next;
    if (change <= tolerance) break;
  }
  return p;
}

// One contact's percussion without the viscous term: exact local solve, prox as the fallback.
Eigen::Vector3d SolveCoulomb(const Contact& c, const Eigen::Vector3d& xi0, double tolerance,
                             const SlipControl& control) {
  Eigen::Vector3d p;
  if (!SolveLocal(c.delassus, c.delassus_inverse, c.mu, xi0, &p, control))
    p = ProxLocal(c.delassus, c.mu, c.r_normal, c.r_tangent, xi0, c.percussion, tolerance);
  return p;
}

// One contact's percussion with the viscous friction of the contact-friction reading:
// P = P_C - h (0, gamma_T,E), gamma_E = xi - bias, P_C obeying Signorini and Coulomb on xi, and
// h = nu dt m_c >= 0 (kg) acting only while P_N > 0 (docs/model.md, "The viscous term"). With
// H = diag(0, h, h) the damping folds into the contact's mass matrix, G^-1 -> G^-1 + H, so that
// xi = xi0' + G' P_C with G' = (G^-1 + H)^-1 and xi0' = G' (G^-1 xi0 + H bias): the same local
// problem as without viscosity, solved exactly by the same branches. If the contact would lift off
// only because of its own viscous traction (xi0_N < 0 <= xi0'_N, a grazing contact), the term is
// dropped: it never acts without load.
Eigen::Vector3d SolveViscous(const Contact& c, const Eigen::Vector3d& xi0, double h,
                             double tolerance, const SlipControl& control) {
  if (xi0.x() >= 0) return Eigen::Vector3d::Zero();
  Eigen::Vector3d rhs = c.delassus_inverse * xi0;  // -(stick percussion) of the viscous problem
  rhs.tail<2>() += h * c.velocity_bias.tail<2>();
  Eigen::Vector3d coulomb = -rhs;
  Eigen::Vector2d xi_t = Eigen::Vector2d::Zero();  // sticking: xi = 0
  if (!(coulomb.x() >= 0 && coulomb.tail<2>().norm() <= c.mu * coulomb.x())) {
    Eigen::Matrix3d mass = c.delassus_inverse;
    mass(1, 1) += h;
    mass(2, 2) += h;
    const Eigen::Matrix3d g = mass.inverse();
    const Eigen::Vector3d xi0_viscous = g * rhs;
    if (xi0_viscous.x() >= 0) return SolveCoulomb(c, xi0, tolerance, control);
    if (c.mu == 0) {
      coulomb = Eigen::Vector3d(-xi0_viscous.x() / g(0, 0), 0, 0);
    } else if (!SolveSlip(g, xi0_viscous, c.mu, &coulomb, control)) {
      coulomb = ProxLocal(g, c.mu, c.r_normal, c.r_tangent, xi0_viscous, c.percussion, tolerance);
    }
    xi_t = (xi0_viscous + g * coulomb).tail<2>();
  }
  // Add the viscous part -h gamma_T,E, gamma_E = xi - bias.
  Eigen::Vector3d p = coulomb;
  p.tail<2>() -= h * (xi_t - c.velocity_bias.tail<2>());
  return p;
}

// Two contacts as one block (ContactSolveMethod::kBlock): the pair problem of the current
// iterate (solver/contact_block.hpp), solved exactly, and its change applied to the velocities.
// With the contact-friction viscosity, H = diag(0, h_i, h_i) folds into G as for one contact,
// G' = (I + G H)^-1 G and xi0' = (I + G H)^-1 (xi0 + G H bias), with h_i from the load shares of
// the previous solution; repeated until the shares agree with the solution's own to the
// tolerance. False, with nothing changed, when the block solve finds no verified case.
bool SolvePairBlock(const Eigen::Matrix3d& rotation, double inv_mass, double tolerance,
                    Eigen::Vector3d& velocity_m_s, Eigen::Vector3d& omega_rad_s,
                    std::vector<Contact>& contacts) {
  Contact& c0 = contacts[0];
  Contact& c1 = contacts[1];
  PairProblem pr;
  pr.g.block<3, 3>(0, 0) = c0.delassus;
  pr.g.block<3, 3>(3, 3) = c1.delassus;
  const Eigen::Matrix3d coupling = inv_mass * c0.directions.transpose() * c1.directions +
                                   c0.arms.transpose() * c1.inv_inertia_arms;
  pr.g.block<3, 3>(0, 3) = coupling;
  pr.g.block<3, 3>(3, 0) = coupling.transpose();
  Vector6d now, xi, bias;
  now << c0.percussion, c1.percussion;
  bias << c0.velocity_bias, c1.velocity_bias;
  xi << c0.directions.transpose() * velocity_m_s + c0.arms.transpose() * omega_rad_s,
      c1.directions.transpose() * velocity_m_s + c1.arms.transpose() * omega_rad_s;
  xi += bias;
  const Vector6d xi0 = xi - pr.g * now;
  // Internal force: +e at contact 0, -e at contact 1, e along the line through the two points
  // where the percussions act (the levers: a predicted contact's may be its touch point), so that
  // the pair exerts no net force or torque and z stays G's null vector.
  const Eigen::Vector3d e = (rotation * (c0.lever_m - c1.lever_m)).normalized();
  pr.null << c0.directions.transpose() * e, -(c1.directions.transpose() * e);
  pr.null.normalize();
  pr.mu[0] = c0.mu;
  pr.mu[1] = c1.mu;

  Vector6d p;
  if (c0.viscous_kg == 0 && c1.viscous_kg == 0) {
    pr.xi0 = xi0;
    if (!SolvePair(pr, now, tolerance, &p)) return false;
  } else {
    Vector6d previous = now;
    bool agreed = false;
    for (int outer = 0; outer < 20 && !agreed; ++outer) {
      const double total = previous(0) + previous(3);
      Vector6d h = Vector6d::Zero();
      if (total > 0) {
        h.segment<2>(1).setConstant(c0.viscous_kg * previous(0) / total);
        h.segment<2>(4).setConstant(c1.viscous_kg * previous(3) / total);
      }
      const Eigen::PartialPivLU<Matrix6d> lu(Matrix6d::Identity() + pr.g * h.asDiagonal());
      PairProblem viscous = pr;
      viscous.g = lu.solve(pr.g);
      viscous.g = 0.5 * (viscous.g + viscous.g.transpose()).eval();
      viscous.xi0 = lu.solve(xi0 + pr.g * h.cwiseProduct(bias));
      // The previous solution as the guess: its statuses are those of its Coulomb part (a
      // slipping contact's |P_T| = mu P_N + h |gamma_T| >= mu P_N) and its slip directions too.
      Vector6d coulomb;
      if (!SolvePair(viscous, previous, tolerance, &coulomb)) return false;
      const Vector6d slip = viscous.xi0 + viscous.g * coulomb - bias;  // gamma_E
      p = coulomb - h.cwiseProduct(slip);
      // Shares of this solution against the ones used: the velocity error they make.
      const double new_total = p(0) + p(3);
      agreed = true;
      for (int i = 0; i < 2; ++i) {
        const double share = new_total > 0 ? p(3 * i) / new_total : 0.0;
        const double h_new = contacts[i].viscous_kg * share;
        const double error = std::abs(h_new - h(3 * i + 1)) * slip.segment<2>(3 * i + 1).norm() *
                             pr.g.block<2, 2>(3 * i + 1, 3 * i + 1).norm();
        agreed = agreed && error <= tolerance;
      }
      previous = p;
    }
    if (!agreed) return false;
  }
  for (int i = 0; i < 2; ++i) {
    Contact& c = contacts[i];
    const Eigen::Vector3d delta = p.segment<3>(3 * i) - c.percussion;
    c.percussion = p.segment<3>(3 * i);
    velocity_m_s += inv_mass * (c.directions * delta);
    omega_rad_s += c.inv_inertia_arms * delta;
  }
  return true;
}

// Gauss-Seidel sweeps after which a pair of contacts that has not converged is solved as one
// block (ContactSolveMethod::kBlockOnStall). On the ramp a pair that converges takes 2.5 sweeps on
// average; those that stall would run to max_iterations.
constexpr int kPairStallSweeps = 20;

// What every sweep of one step's contact solve uses.
struct SweepSetting {
  double inv_mass_1_kg;
  double tolerance_m_s;        // of the solve (SolverOptions::tolerance_m_s)
  double local_tolerance_m_s;  // of each contact's exact solve: 1e-3 of the solve's
  double radius_m;             // the rock's bounding radius: where dw is felt most
  bool viscous_friction;       // ViscousReading::kContactFriction
  bool block;                  // ContactSolveMethod::kBlock
  bool single;                 // one contact: solved exactly in one sweep, its change not needed
};

// Per-contact Jacobians, step lengths and warm start: each contact's Delassus block and prox
// steps, its velocity bias (restitution and gap) and viscous mass, and the previous step's
// percussion (re-expressed in this frame, made admissible) applied to the velocities.
void PrepareContacts(const Scene& scene, const RockShape& rock, double dt_s,
                     const Eigen::Matrix3d& rotation, const EffectiveInertia& inertia,
                     const Eigen::Vector3d& v_begin, const Eigen::Vector3d& omega_begin,
                     Eigen::Vector3d& velocity_m_s, Eigen::Vector3d& omega_rad_s,
                     StepWorkspace& workspace) {
  const SolverOptions& opt = scene.options;
  const Eigen::Vector3d inv_inertia = rock.inertia_kg_m2.cwiseInverse() / inertia.inertia_scale;
  const Eigen::Vector3d restitution(opt.normal_restitution, opt.tangential_restitution,
                                    opt.tangential_restitution);
  const bool with_restitution = opt.normal_restitution != 0 || opt.tangential_restitution != 0;
  const double inv_mass = 1.0 / inertia.mass_kg;
  const double inv_dt = 1.0 / dt_s;
  const bool viscous_friction = opt.viscous == ViscousReading::kContactFriction;
  for (Contact& c : workspace.contacts) {
    const Eigen::Vector3d& b = c.lever_m;
    const Eigen::Matrix3d body_dirs = rotation.transpose() * c.directions;
    for (int k = 0; k < 3; ++k) c.arms.col(k) = b.cross(body_dirs.col(k));
    c.inv_inertia_arms = inv_inertia.asDiagonal() * c.arms;
    // Delassus block G = W' M^-1 W for this contact.
    Eigen::Matrix3d& g = c.delassus;
    g = c.arms.transpose() * c.inv_inertia_arms;
    g.diagonal().array() += inv_mass;
    c.delassus_inverse = g.inverse();
    c.r_normal = opt.prox_alpha / g(0, 0);
    const double mean = 0.5 * (g(1, 1) + g(2, 2));
    const double half_diff = 0.5 * (g(1, 1) - g(2, 2));
    c.r_tangent = opt.prox_alpha / (mean + std::sqrt(half_diff * half_diff + g(1, 2) * g(1, 2)));
    // Newton's law on a closed contact, and on a predicted one that the vertex reaches within the
    // step at its begin velocity (it rebounds from where it stands, short of the surface by less
    // than one step's travel); the plastic gap law on a predicted one it does not reach.
    c.velocity_bias = Eigen::Vector3d((c.gap_m + c.lift_m) * inv_dt, 0, 0);
    if (with_restitution) {
      const Eigen::Vector3d gamma_begin =
          c.directions.transpose() * v_begin + c.arms.transpose() * omega_begin;
      if (c.gap_m == 0 || c.gap_m + dt_s * gamma_begin.x() < 0)
        c.velocity_bias = restitution.cwiseProduct(gamma_begin);
    }
    c.viscous_kg =
        viscous_friction ? scene.ground.params(c.ground).nu_1_s * dt_s * rock.mass_kg : 0.0;
    c.percussion.setZero();
    if (workspace.last_closed[c.vertex] && !c.corner) {
      // Previous step's percussion, re-expressed in this frame and made admissible.
      Eigen::Vector3d p = c.directions.transpose() * workspace.last_percussion[c.vertex];
      p.x() = std::max(0.0, p.x());
      p.tail<2>() = ProjectDisk(p.tail<2>(), c.mu * p.x());
      c.percussion = p;
      velocity_m_s += inv_mass * (c.directions * p);
      omega_rad_s += c.inv_inertia_arms * p;
    }
  }
}

// One Gauss-Seidel sweep over the contacts, each solved exactly with the others held fixed;
// returns the largest velocity change it made at a point of the rock (m/s), 0 for a single
// contact. Inlined into the solve's loop: as a call it costs 0.9 % of the ramp's instructions
// (bench/ramp_bench.cpp).
[[gnu::always_inline]] inline double Sweep(const SweepSetting& setting,
                                           std::vector<Contact>& contacts,
                                           Eigen::Vector3d& velocity_m_s,
                                           Eigen::Vector3d& omega_rad_s) {
  double max_change = 0;
  // Contact-friction viscosity: contact i's share of the rock's mass is its share of the total
  // normal percussion, taken from the current iterate (all of it when no other contact carries
  // load, which makes a single contact's solve exact).
  double total_normal = 0;
  if (setting.viscous_friction)
    for (const Contact& c : contacts) total_normal += c.percussion.x();
  for (Contact& c : contacts) {
    const Eigen::Vector3d xi = c.directions.transpose() * velocity_m_s +
                               c.arms.transpose() * omega_rad_s + c.velocity_bias;
    const Eigen::Vector3d xi0 = xi - c.delassus * c.percussion;
    // Block method: the slip Newton starts from this contact's slipping iterate and stops at
    // a tenth of the tolerance.
    SlipControl control;
    Eigen::Vector2d start;
    if (setting.block) {
      control.f_tolerance = 0.1 * setting.tolerance_m_s;
      const double tangential = c.percussion.tail<2>().norm();
      if (c.percussion.x() > 0 && tangential >= c.mu * c.percussion.x() * (1 - 1e-6) &&
          tangential > 0) {
        start = c.percussion.tail<2>() / tangential;
        control.start = &start;
      }
    }
    Eigen::Vector3d p;
    if (c.viscous_kg > 0) {
      const double own = c.percussion.x();
      const double others = total_normal - own;
      const double share = others > 0 ? own / (own + others) : 1.0;
      p = share > 0
              ? SolveViscous(c, xi0, share * c.viscous_kg, setting.local_tolerance_m_s, control)
              : SolveCoulomb(c, xi0, setting.local_tolerance_m_s, control);
      total_normal += p.x() - own;
    } else {
      p = SolveCoulomb(c, xi0, setting.local_tolerance_m_s, control);
    }
    const Eigen::Vector3d delta = p - c.percussion;
    if (delta.isZero(0.0)) continue;
    c.percussion = p;
    const Eigen::Vector3d dv = setting.inv_mass_1_kg * (c.directions * delta);
    const Eigen::Vector3d dw = c.inv_inertia_arms * delta;
    velocity_m_s += dv;
    omega_rad_s += dw;
    if (!setting.single)
      max_change = std::max(max_change, dv.norm() + setting.radius_m * dw.norm());
  }
  return max_change;
}

// Keeps this step's percussions (world frame) as the next step's warm start.
void RememberPercussions(StepWorkspace& workspace, ContactSolveReport& report) {
  workspace.ForgetPercussions();
  for (const Contact& c : workspace.contacts) {
    if (c.corner) {  // its vertex's closed contact comes first
      workspace.last_percussion[c.vertex] += c.directions * c.percussion;
      continue;
    }
    workspace.last_closed[c.vertex] = 1;
    workspace.last_closed_list.push_back(c.vertex);
    workspace.last_percussion[c.vertex] = c.directions * c.percussion;
    if (c.percussion.x() > 0) report.loaded = true;
  }
}

}  // namespace

ContactSolveReport SolveContacts(const Scene& scene, const RockShape& rock, double dt_s,
                                 const Eigen::Matrix3d& rotation, const EffectiveInertia& inertia,
                                 const Eigen::Vector3d& v_begin, const Eigen::Vector3d& omega_begin,
                                 Eigen::Vector3d& velocity_m_s, Eigen::Vector3d& omega_rad_s,
                                 StepWorkspace& workspace) {
  ContactSolveReport report;
  const SolverOptions& opt = scene.options;
  PrepareContacts(scene, rock, dt_s, rotation, inertia, v_begin, omega_begin, velocity_m_s,
                  omega_rad_s, workspace);

  // Gauss-Seidel over the contacts until a sweep changes no contact velocity by more than the
  // tolerance, or max_iterations sweeps.
  const SweepSetting setting{.inv_mass_1_kg = 1.0 / inertia.mass_kg,
                             .tolerance_m_s = opt.tolerance_m_s,
                             .local_tolerance_m_s = 1e-3 * opt.tolerance_m_s,
                             .radius_m = rock.bounding_radius_m,
                             .viscous_friction = opt.viscous == ViscousReading::kContactFriction,
                             .block = opt.contact_solve == ContactSolveMethod::kBlock,
                             .single = workspace.contacts.size() == 1};
  // Two contacts as one block: with the block method after the first sweep; on stall after
  // kPairStallSweeps sweeps; never with Gauss-Seidel alone.
  const int pair_block_after = setting.block ? 1
                               : opt.contact_solve == ContactSolveMethod::kBlockOnStall
                                   ? kPairStallSweeps
                                   : 0;
  report.converged = false;
  for (int iter = 1; iter <= opt.max_iterations; ++iter) {
    const double max_change = Sweep(setting, workspace.contacts, velocity_m_s, omega_rad_s);
    report.iterations = iter;
    // One contact is solved exactly by its local solve: no second sweep is needed.
    if (setting.single || max_change <= opt.tolerance_m_s) {
      report.converged = true;
      break;
    }
    // The two contacts of an edge as one exact block solve; when it finds no verified case the
    // sweeps go on.
    if (workspace.contacts.size() == 2 && iter == pair_block_after &&
        SolvePairBlock(rotation, setting.inv_mass_1_kg, opt.tolerance_m_s, velocity_m_s,
                       omega_rad_s, workspace.contacts)) {
      report.iterations = iter + 1;
      report.converged = true;
      break;
    }
  }
  RememberPercussions(workspace, report);
  return report;
}

}  // namespace talus
