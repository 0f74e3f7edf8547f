#pragma once
// Block solve of two coupled contacts (a rock on an edge): the 6 x 6 Signorini-Coulomb problem
// solved exactly, case by case, instead of by Gauss-Seidel sweeps.

#include <Eigen/Core>

namespace talus {

using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix6d = Eigen::Matrix<double, 6, 6>;

// The contact problem of two contacts, each in its own frame (n, t1, t2): contact velocities
// xi = xi0 + G P (m/s) with P = (P_N, P_T1, P_T2) of contact 0, then of contact 1 (N s). G is the
// Delassus matrix W' M^-1 W (1/kg), symmetric positive semidefinite and of rank 5 for a rigid
// body: equal and opposite forces along the line through the two contact points do nothing,
// G z = 0 with z = `null` (unit length). Such an internal force is all that distinguishes the
// percussions of two solutions with the same velocities.
struct PairProblem {
  Matrix6d g;
  Vector6d xi0;
  Vector6d null;
  double mu[2] = {0, 0};
};

enum class ContactStatus : unsigned char { kSeparated, kSticking, kSlipping };

// A tangential percussion projected onto the friction disk of radius bound (the one contact's
// solve and the pair's share it).
inline Eigen::Vector2d ProjectDisk(const Eigen::Vector2d& p, double bound) {
  const double norm = p.norm();
  return norm > bound ? Eigen::Vector2d(p * (bound / norm)) : p;
}

// Solves Signorini (xi_N >= 0, P_N >= 0, xi_N P_N = 0) and Coulomb (|P_T| <= mu P_N; sticking:
// xi_T = 0; slipping: xi_N = 0 and P_T = mu P_N d with d = -xi_T / |xi_T|) at both contacts. The
// nine active-set cases (each contact separated, sticking or slipping) are tried, the one that
// `guess` (a percussion, e.g. a Gauss-Seidel iterate) suggests first, its slip directions as
// Newton's start; each case is solved exactly (a linear solve for given slip directions, Newton on
// the slip angles until the slip velocity normal to d is below 0.1 tolerance_m_s; both sticking:
// the minimum-norm solution moved along z into both friction cones) and accepted only when every
// law holds to tolerance_m_s. Returns false when no case does; *p is then unchanged.
bool SolvePair(const PairProblem& problem, const Vector6d& guess, double tolerance_m_s,
               Vector6d* p);

// Largest violation of the laws above by the percussion p (m/s: a velocity residual, or a
// percussion's excess over the friction cone times the contact's G_NN), for tests and checks.
double PairLawViolation(const PairProblem& problem, const Vector6d& p);

}  // namespace talus
