#pragma once
// Kinematic stages of the midpoint step: half-step drift and the free rotation.

#include <Eigen/Core>

#include "solver/state.hpp"

namespace talus {

// Advances position by h v and orientation by the body angular velocity over h (exact
// quaternion exponential of a constant body rate), then renormalises the quaternion.
void Drift(RockState& state, double h_s);

// Implicit midpoint rule for the torque-free Euler equations:
// Theta (W_f - W_b) + dt W_m x (Theta W_m) = 0, W_m = (W_b + W_f)/2, solved by Newton's method.
// It conserves kinetic energy and |angular momentum| exactly (both are quadratic invariants),
// which keeps rotation about the major axis stable (Leine et al. 2021).
Eigen::Vector3d FreeRotation(const Eigen::Vector3d& inertia_kg_m2, const Eigen::Vector3d& omega_b,
                             double dt_s);

}  // namespace talus
