#include "solver/kinematics.hpp"

#include <cmath>
#include <cstring>
#include <limits>

namespace talus {

void Drift(RockState& state, double h_s, DriftTurn* last) {
  state.position_m += h_s * state.velocity_m_s;
  DriftTurn computed;
  DriftTurn& t = last ? *last : computed;
  const Eigen::Vector3d& w = state.angular_velocity_rad_s;
  // Compared bit for bit (0 and -0 give turns of different bits).
  if (std::memcmp(t.rate_rad_s.data(), w.data(), sizeof(double) * 3) != 0 ||
      std::memcmp(&t.h_s, &h_s, sizeof(double)) != 0) {
    t.rate_rad_s = w;
    t.h_s = h_s;
    const double rate = w.norm();
    t.turns = rate > 0;
    if (t.turns) {
      const double half_angle = 0.5 * rate * h_s;
      const Eigen::Vector3d axis_part = (std::sin(half_angle) / rate) * w;
      t.turn = {std::cos(half_angle), axis_part.x(), axis_part.y(), axis_part.z()};
    }
  }
  if (t.turns) state.orientation = state.orientation * t.turn;
  state.orientation.normalize();
}

namespace {

// Newton's method on the midpoint rate m = (W_b + W_f) / 2, written out per component (Theta is
// diagonal): F(m) = 2 Theta (m - W_b) + dt m x (Theta m) = 0, with (m x Theta m)_x = (theta_z -
// theta_y) m_y m_z and its cyclic permutations, and J = dF/dm = 2 Theta + dt (skew(m) Theta -
// skew(Theta m)), solved by its cofactors. Then W_f = 2 m - W_b. The same root as Newton on W_f
// with 3 x 3 matrices (to round-off: at most 8e-16 relative over 10^5 random rates up to dt |W| of
// 4), at a third of its cost (bench/README.md, "Free rotation written out"). False when it has not
// converged in 20 iterations (seen from dt |W| between 4 and 6 on a 45:80:110 inertia), with
// `omega_f` then untouched.
bool MidpointRule(const Eigen::Vector3d& inertia_kg_m2, const Eigen::Vector3d& omega_b, double dt_s,
                  Eigen::Vector3d* omega_f) {
  const double scale2 = omega_b.squaredNorm();
  const Eigen::Vector3d& th = inertia_kg_m2;
  const Eigen::Vector3d& w = omega_b;
  // F_x = 2 theta_x (m_x - w_x) - a_x m_y m_z, a_x = dt (theta_y - theta_z), cyclic.
  const double ax = dt_s * (th.y() - th.z());
  const double ay = dt_s * (th.z() - th.x());
  const double az = dt_s * (th.x() - th.y());
  const double jxx = 2 * th.x(), jyy = 2 * th.y(), jzz = 2 * th.z();
  double mx = w.x(), my = w.y(), mz = w.z();
  // Quadratic convergence: once a step of W_f (twice m's) is below 1e-9 |W_b|, what is left is
  // round-off.
  const double tolerance2 = 0.25e-18 * scale2;
  for (int iter = 0; iter < 20; ++iter) {
    const double fx = jxx * (mx - w.x()) - ax * my * mz;
    const double fy = jyy * (my - w.y()) - ay * mz * mx;
    const double fz = jzz * (mz - w.z()) - az * mx * my;
    const double jxy = -ax * mz, jxz = -ax * my;
    const double jyx = -ay * mz, jyz = -ay * mx;
    const double jzx = -az * my, jzy = -az * mx;
    // Cofactors C_rc of J; J^-1 = C' / det.
    const double cxx = jyy * jzz - jyz * jzy, cxy = jyz * jzx - jyx * jzz,
                 cxz = jyx * jzy - jyy * jzx;
    const double cyx = jxz * jzy - jxy * jzz, cyy = jxx * jzz - jxz * jzx,
                 cyz = jxy * jzx - jxx * jzy;
    const double czx = jxy * jyz - jxz * jyy, czy = jxz * jyx - jxx * jyz,
                 czz = jxx * jyy - jxy * jyx;
    const double inv_det = 1.0 / (jxx * cxx + jxy * cxy + jxz * cxz);
    const double dx = (cxx * fx + cyx * fy + czx * fz) * inv_det;
    const double dy = (cxy * fx + cyy * fy + czy * fz) * inv_det;
    const double dz = (cxz * fx + cyz * fy + czz * fz) * inv_det;
    mx -= dx;
    my -= dy;
    mz -= dz;
    if (dx * dx + dy * dy + dz * dz <= tolerance2) {
      *omega_f = {2 * mx - w.x(), 2 * my - w.y(), 2 * mz - w.z()};
      return true;
    }
  }
  return false;
}

constexpr int kMaxHalvings = 10;

// A step Newton cannot take is taken as two halves, each conserving both invariants, and each
// halved again when Newton cannot take it either. Without this a non-converged iterate was
// returned: at dt |W| = 10, 11 % of random rates (45:80:110) came back with neither invariant kept,
// some with 180 times their energy. At 2^-10 of a step of at most 0.1 s Newton converges below
// about 4e4 rad/s; past that depth a part is left unturned.
Eigen::Vector3d InHalves(const Eigen::Vector3d& inertia_kg_m2, const Eigen::Vector3d& omega_b,
                         double dt_s, int depth) {
  const double half = 0.5 * dt_s;
  Eigen::Vector3d mid, end;
  if (!MidpointRule(inertia_kg_m2, omega_b, half, &mid))
    mid = depth < kMaxHalvings ? InHalves(inertia_kg_m2, omega_b, half, depth + 1) : omega_b;
  if (!MidpointRule(inertia_kg_m2, mid, half, &end))
    end = depth < kMaxHalvings ? InHalves(inertia_kg_m2, mid, half, depth + 1) : mid;
  return end;
}

}  // namespace

Eigen::Vector3d FreeRotation(const Eigen::Vector3d& inertia_kg_m2, const Eigen::Vector3d& omega_b,
                             double dt_s) {
  const double scale2 = omega_b.squaredNorm();
  if (!(scale2 > 0 && scale2 < std::numeric_limits<double>::infinity())) return omega_b;
  Eigen::Vector3d omega_f;
  if (MidpointRule(inertia_kg_m2, omega_b, dt_s, &omega_f)) return omega_f;
  return InHalves(inertia_kg_m2, omega_b, dt_s, 1);
}

}  // namespace talus
