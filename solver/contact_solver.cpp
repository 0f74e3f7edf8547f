#include "solver/contact_solver.hpp"

#include <algorithm>
#include <cmath>

namespace talus {
namespace {

// Projects the tangential percussion onto the friction disk of radius bound.
Eigen::Vector2d ProjectDisk(const Eigen::Vector2d& p, double bound) {
  const double norm = p.norm();
  return norm > bound ? Eigen::Vector2d(p * (bound / norm)) : p;
}

}  // namespace

ContactSolveReport SolveContacts(const Scene& scene, const Eigen::Matrix3d& rotation,
                                 double mass_eff_kg, const Eigen::Vector3d& v_begin,
                                 const Eigen::Vector3d& omega_begin, Eigen::Vector3d& velocity_m_s,
                                 Eigen::Vector3d& omega_rad_s, StepWorkspace& workspace) {
  ContactSolveReport report;
  const RockShape& rock = scene.rock;
  const SolverOptions& opt = scene.options;
  const Eigen::Vector3d inv_inertia = rock.inertia_kg_m2.cwiseInverse();
  const Eigen::Vector3d restitution(opt.normal_restitution, opt.tangential_restitution,
                                    opt.tangential_restitution);
  const bool with_restitution = opt.normal_restitution != 0 || opt.tangential_restitution != 0;
  const double inv_mass = 1.0 / mass_eff_kg;

  // Per-contact Jacobians, step lengths and warm start.
  for (Contact& c : workspace.contacts) {
    const Eigen::Vector3d& b = rock.vertices_m[c.vertex];
    const Eigen::Matrix3d body_dirs = rotation.transpose() * c.directions;
    for (int k = 0; k < 3; ++k) c.arms.col(k) = b.cross(body_dirs.col(k));
    c.inv_inertia_arms = inv_inertia.asDiagonal() * c.arms;
    // Delassus block G = W' M^-1 W for this contact.
    Eigen::Matrix3d g = c.arms.transpose() * c.inv_inertia_arms;
    g.diagonal().array() += inv_mass;
    c.r_normal = opt.prox_alpha / g(0, 0);
    const double mean = 0.5 * (g(1, 1) + g(2, 2));
    const double half_diff = 0.5 * (g(1, 1) - g(2, 2));
    c.r_tangent = opt.prox_alpha / (mean + std::sqrt(half_diff * half_diff + g(1, 2) * g(1, 2)));
    c.restitution_term =
        with_restitution
            ? Eigen::Vector3d(restitution.cwiseProduct(c.directions.transpose() * v_begin +
                                                       c.arms.transpose() * omega_begin))
            : Eigen::Vector3d::Zero();
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

  const double radius = rock.bounding_radius_m;
  report.converged = false;
  for (int iter = 1; iter <= opt.max_iterations; ++iter) {
    double max_change = 0;
    for (Contact& c : workspace.contacts) {
      const Eigen::Vector3d xi = c.directions.transpose() * velocity_m_s +
                                 c.arms.transpose() * omega_rad_s + c.restitution_term;
      Eigen::Vector3d p;
      p.x() = std::max(0.0, c.percussion.x() - c.r_normal * xi.x());
      p.tail<2>() = ProjectDisk(c.percussion.tail<2>() - c.r_tangent * xi.tail<2>(), c.mu * p.x());
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
    if (max_change <= opt.tolerance_m_s) {
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
