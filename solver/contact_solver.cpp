#include "solver/contact_solver.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>

namespace talus {
namespace {

// Projects the tangential percussion onto the friction disk of radius bound.
Eigen::Vector2d ProjectDisk(const Eigen::Vector2d& p, double bound) {
  const double norm = p.norm();
  return norm > bound ? Eigen::Vector2d(p * (bound / norm)) : p;
}

// Slip branch of one contact: P = P_N (1, mu d) with d a unit vector opposite to the tangential
// velocity of gamma = xi0 + G P, and gamma_N = 0. Newton's method on the angle of d for
// F = d x gamma_T = 0 (analytic derivative; d is turned without trigonometric calls), started
// opposite to the tangential velocity that a frictionless impact would leave.
bool SolveSlip(const Eigen::Matrix3d& g, const Eigen::Vector3d& xi0, double mu,
               Eigen::Vector3d* p) {
  const double a = g(0, 0);
  const Eigen::Vector2d b = g.block<2, 1>(1, 0);
  const Eigen::Matrix2d c = g.block<2, 2>(1, 1);
  auto cross = [](const Eigen::Vector2d& u, const Eigen::Vector2d& v) {
    return u.x() * v.y() - u.y() * v.x();
  };
  Eigen::Vector2d d = -(xi0.tail<2>() - (xi0.x() / a) * b);
  if (d.squaredNorm() == 0) return false;
  d.normalize();
  double normal = 0, denominator = 0;
  Eigen::Vector2d gamma_t;
  for (int iter = 0; iter < 40; ++iter) {
    const Eigen::Vector2d d_perp(-d.y(), d.x());  // d rotated by +90 degrees: dd/dphi
    denominator = a + mu * b.dot(d);
    normal = -xi0.x() / denominator;
    const Eigen::Vector2d lever = b + mu * (c * d);
    gamma_t = xi0.tail<2>() + normal * lever;
    const double f = cross(d, gamma_t);
    const double normal_slope = -normal * mu * b.dot(d_perp) / denominator;
    const Eigen::Vector2d gamma_slope = normal_slope * lever + normal * mu * (c * d_perp);
    const double f_slope = -d.dot(gamma_t) + cross(d, gamma_slope);
    if (!(f_slope != 0) || !std::isfinite(f_slope)) return false;
    const double step = std::clamp(-f / f_slope, -0.5, 0.5);
    d = (d + step * d_perp).normalized();  // turns d by atan(step)
    if (std::abs(step) < 1e-13) break;
  }
  denominator = a + mu * b.dot(d);
  normal = -xi0.x() / denominator;
  gamma_t = xi0.tail<2>() + normal * (b + mu * (c * d));
  // Admissible only with a compressive normal percussion and d opposite to the slip velocity.
  if (!(denominator > 0 && normal >= 0 && d.dot(gamma_t) <= 0)) return false;
  if (std::abs(cross(d, gamma_t)) > 1e-9 * (gamma_t.norm() + 1e-12)) return false;
  *p = Eigen::Vector3d(normal, mu * normal * d.x(), mu * normal * d.y());
  return true;
}

// Exact solution of one contact's laws with all other percussions held fixed: gamma = xi0 + G P
// with Signorini in the normal and Coulomb in the tangent plane. Tries separation, then sticking,
// then slipping. Returns false when the slip iteration does not converge.
bool SolveLocal(const Contact& c, const Eigen::Vector3d& xi0, Eigen::Vector3d* p) {
  if (xi0.x() >= 0) {
    p->setZero();
    return true;
  }
  const Eigen::Vector3d stick = -(c.delassus_inverse * xi0);
  if (stick.x() >= 0 && stick.tail<2>().norm() <= c.mu * stick.x()) {
    *p = stick;
    return true;
  }
  if (c.mu == 0) {
    *p = Eigen::Vector3d(-xi0.x() / c.delassus(0, 0), 0, 0);
    return true;
  }
  return SolveSlip(c.delassus, xi0, c.mu, p);
}

// Fallback: proximal-point iterations on the contact's own 3 x 3 problem.
Eigen::Vector3d ProxLocal(const Contact& c, const Eigen::Vector3d& xi0, Eigen::Vector3d p,
                          double tolerance) {
  for (int iter = 0; iter < 1000; ++iter) {
    const Eigen::Vector3d xi = xi0 + c.delassus * p;
    Eigen::Vector3d next;
    next.x() = std::max(0.0, p.x() - c.r_normal * xi.x());
    next.tail<2>() = ProjectDisk(p.tail<2>() - c.r_tangent * xi.tail<2>(), c.mu * next.x());
    const double change = (c.delassus * (next - p)).norm();
    p = next;
    if (change <= tolerance) break;
  }
  return p;
}

}  // namespace

ContactSolveReport SolveContacts(const Scene& scene, const RockShape& rock,
                                 const Eigen::Matrix3d& rotation, double mass_eff_kg,
                                 const Eigen::Vector3d& v_begin, const Eigen::Vector3d& omega_begin,
                                 Eigen::Vector3d& velocity_m_s, Eigen::Vector3d& omega_rad_s,
                                 StepWorkspace& workspace) {
  ContactSolveReport report;
  const SolverOptions& opt = scene.options;
  const Eigen::Vector3d inv_inertia = rock.inertia_kg_m2.cwiseInverse();
  const Eigen::Vector3d restitution(opt.normal_restitution, opt.tangential_restitution,
                                    opt.tangential_restitution);
  const bool with_restitution = opt.normal_restitution != 0 || opt.tangential_restitution != 0;
  const double inv_mass = 1.0 / mass_eff_kg;
  const double inv_dt = 1.0 / opt.dt_s;

  // Per-contact Jacobians, step lengths and warm start.
  for (Contact& c : workspace.contacts) {
    const Eigen::Vector3d& b = rock.vertices_m[c.vertex];
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
    c.velocity_bias =
        with_restitution
            ? Eigen::Vector3d(restitution.cwiseProduct(c.directions.transpose() * v_begin +
                                                       c.arms.transpose() * omega_begin))
            : Eigen::Vector3d::Zero();
    c.velocity_bias.x() += c.gap_m * inv_dt;
    c.percussion.setZero();
    if (workspace.last_closed[c.vertex]) {
      // Previous step's percussion, re-expressed in this frame and made admissible.
      Eigen::Vector3d p = c.directions.transpose() * workspace.last_percussion[c.vertex];
      p.x() = std::max(0.0, p.x());
      p.tail<2>() = ProjectDisk(p.tail<2>(), c.mu * p.x());
      c.percussion = p;
      velocity_m_s += inv_mass * (c.directions * p);
      omega_rad_s += c.inv_inertia_arms * p;
    }
  }

  // Gauss-Seidel over the contacts, each solved exactly with the others held fixed.
  const double radius = rock.bounding_radius_m;
  report.converged = false;
  for (int iter = 1; iter <= opt.max_iterations; ++iter) {
    double max_change = 0;
    for (Contact& c : workspace.contacts) {
      const Eigen::Vector3d xi = c.directions.transpose() * velocity_m_s +
                                 c.arms.transpose() * omega_rad_s + c.velocity_bias;
      const Eigen::Vector3d xi0 = xi - c.delassus * c.percussion;
      Eigen::Vector3d p;
      if (!SolveLocal(c, xi0, &p)) p = ProxLocal(c, xi0, c.percussion, 1e-3 * opt.tolerance_m_s);
      const Eigen::Vector3d delta = p - c.percussion;
      if (delta.isZero(0.0)) continue;
      c.percussion = p;
      const Eigen::Vector3d dv = inv_mass * (c.directions * delta);
      const Eigen::Vector3d dw = c.inv_inertia_arms * delta;
      velocity_m_s += dv;
      omega_rad_s += dw;
      max_change = std::max(max_change, dv.norm() + radius * dw.norm());
    }
    report.iterations = iter;
    // One contact is solved exactly by its local solve: no second sweep is needed.
    if (max_change <= opt.tolerance_m_s || workspace.contacts.size() == 1) {
      report.converged = true;
      break;
    }
  }

  workspace.ForgetPercussions();
  for (const Contact& c : workspace.contacts) {
    workspace.last_closed[c.vertex] = 1;
    workspace.last_closed_list.push_back(c.vertex);
    workspace.last_percussion[c.vertex] = c.directions * c.percussion;
    if (c.percussion.x() > 0) report.loaded = true;
  }
  return report;
}

}  // namespace talus
