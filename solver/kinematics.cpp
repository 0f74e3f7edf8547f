#include "solver/kinematics.hpp"

#include <Eigen/LU>  // fixed-size inverse
#include <cmath>

namespace talus {

void Drift(RockState& state, double h_s) {
  state.position_m += h_s * state.velocity_m_s;
  const Eigen::Vector3d& w = state.angular_velocity_rad_s;
  const double rate = w.norm();
  if (rate > 0) {
    const double half_angle = 0.5 * rate * h_s;
    const Eigen::Vector3d axis_part = (std::sin(half_angle) / rate) * w;
    const Eigen::Quaterniond dq(std::cos(half_angle), axis_part.x(), axis_part.y(), axis_part.z());
    state.orientation = state.orientation * dq;
  }
  state.orientation.normalize();
}

namespace {
Eigen::Matrix3d Skew(const Eigen::Vector3d& a) {
  Eigen::Matrix3d s;
  s << 0, -a.z(), a.y(), a.z(), 0, -a.x(), -a.y(), a.x(), 0;
  return s;
}
}  // namespace

Eigen::Vector3d FreeRotation(const Eigen::Vector3d& inertia_kg_m2, const Eigen::Vector3d& omega_b,
                             double dt_s) {
  if (omega_b.squaredNorm() == 0) return omega_b;
  const Eigen::DiagonalMatrix<double, 3> theta(inertia_kg_m2);
  Eigen::Vector3d omega_f = omega_b;
  const double scale = omega_b.norm();
  for (int iter = 0; iter < 20; ++iter) {
    const Eigen::Vector3d wm = 0.5 * (omega_b + omega_f);
    const Eigen::Vector3d lm = theta * wm;
    const Eigen::Vector3d residual = theta * (omega_f - omega_b) + dt_s * wm.cross(lm);
    // d/dW_f [dt W_m x Theta W_m] = (dt/2) (skew(W_m) Theta - skew(Theta W_m)).
    Eigen::Matrix3d jacobian = 0.5 * dt_s * (Skew(wm) * theta - Skew(lm));
    jacobian.diagonal() += inertia_kg_m2;
    const Eigen::Vector3d delta = jacobian.inverse() * residual;  // closed-form 3 x 3 inverse
    omega_f -= delta;
    // Quadratic convergence: the error left after a step of 1e-9 is round-off.
    if (delta.norm() <= 1e-9 * scale) break;
  }
  return omega_f;
}

}  // namespace talus
