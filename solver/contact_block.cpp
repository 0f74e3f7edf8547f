#include "solver/contact_block.hpp"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <cmath>

namespace talus {
namespace {

using Eigen::Vector2d;
using Eigen::Vector3d;

double Cross(const Vector2d& u, const Vector2d& v) { return u.x() * v.y() - u.y() * v.x(); }

// Every law at both contacts, for the statuses the solution claims (tolerance in m/s).
bool Verify(const PairProblem& pr, const std::array<ContactStatus, 2>& status,
            const std::array<Vector2d, 2>& d, const Vector6d& p, const Vector6d& xi,
            double tolerance) {
  for (int i = 0; i < 2; ++i) {
    const Vector3d pi = p.segment<3>(3 * i), xii = xi.segment<3>(3 * i);
    const double mu = pr.mu[i];
    switch (status[i]) {
      case ContactStatus::kSeparated:
        if (!(xii.x() >= -tolerance)) return false;
        break;
      case ContactStatus::kSticking:
        if (!(pi.x() >= 0 && pi.tail<2>().norm() <= mu * pi.x() * (1 + 1e-9)) ||
            !(xii.lpNorm<Eigen::Infinity>() <= tolerance))
          return false;
        break;
      case ContactStatus::kSlipping:
        if (!(pi.x() >= 0 && std::abs(xii.x()) <= tolerance)) return false;
        if (mu > 0 && !(d[i].dot(xii.tail<2>()) <= tolerance &&
                        std::abs(Cross(d[i], xii.tail<2>())) <= tolerance))
          return false;
        break;
    }
  }
  return true;
}

// Feasible interval [lo, hi] of t for a + t c in the friction cone of coefficient mu (an interval,
// the preimage of a convex cone); false when empty.
bool ConeInterval(const Vector3d& a, const Vector3d& c, double mu, double* lo, double* hi) {
  auto feasible = [&](double t) {
    const Vector3d x = a + t * c;
    return x.x() >= 0 && x.tail<2>().squaredNorm() <= mu * mu * x.x() * x.x();
  };
  // Breakpoints: where the normal part or mu^2 N^2 - |T|^2 changes sign.
  std::array<double, 3> points{};
  int count = 0;
  if (c.x() != 0) points[count++] = -a.x() / c.x();
  const double qa = mu * mu * c.x() * c.x() - c.tail<2>().squaredNorm();
  const double qb = 2 * (mu * mu * a.x() * c.x() - a.tail<2>().dot(c.tail<2>()));
  const double qc = mu * mu * a.x() * a.x() - a.tail<2>().squaredNorm();
  const double scale = std::abs(qa) + std::abs(qb) + std::abs(qc);
  if (std::abs(qa) > 1e-14 * scale) {
    const double disc = qb * qb - 4 * qa * qc;
    if (disc >= 0) {
      const double root = std::sqrt(disc);
      const double q = -0.5 * (qb + std::copysign(root, qb));
      points[count++] = q / qa;
      if (q != 0) points[count++] = qc / q;
    }
  } else if (qb != 0) {
    points[count++] = -qc / qb;
  }
  std::sort(points.begin(), points.begin() + count);
  // Probe each piece between breakpoints, and the breakpoints themselves.
  double found_lo = INFINITY, found_hi = -INFINITY;
  auto take = [&](double from, double to) {
    found_lo = std::min(found_lo, from);
    found_hi = std::max(found_hi, to);
  };
  if (count == 0) {
    if (feasible(0)) take(-INFINITY, INFINITY);
  } else {
    const double span = 1 + std::abs(points[0]) + std::abs(points[count - 1]);
    if (feasible(points[0] - span)) take(-INFINITY, points[0]);
    for (int k = 0; k < count; ++k) {
      if (feasible(points[k])) take(points[k], points[k]);
      if (k + 1 < count && feasible(0.5 * (points[k] + points[k + 1])))
        take(points[k], points[k + 1]);
    }
    if (feasible(points[count - 1] + span)) take(points[count - 1], INFINITY);
  }
  if (!(found_lo <= found_hi)) return false;
  *lo = found_lo;
  *hi = found_hi;
  return true;
}

// The active-set cases of one pair problem.
class PairCases {
 public:
  PairCases(const PairProblem& pr, double tolerance) : pr_(pr), tolerance_(tolerance) {}

  // Solves the case `status` (slip directions d as Newton's start); true when it verifies.
  bool Solve(const std::array<ContactStatus, 2>& status, const std::array<Vector2d, 2>& d,
             const Vector6d& guess, Vector6d* p) const {
    int k = 0;
    for (ContactStatus s : status)
      k += s == ContactStatus::kSticking ? 3 : s == ContactStatus::kSlipping ? 1 : 0;
    switch (k) {
      case 0:
        return SolveCase<0>(status, d, p);
      case 1:
        return SolveCase<1>(status, d, p);
      case 2:
        return SolveCase<2>(status, d, p);
      case 3:
        return SolveCase<3>(status, d, p);
      case 4:
        return SolveCase<4>(status, d, p);
      default:
        return SolveBothSticking(guess, p);
    }
  }

 private:
  // A case with K unknowns: 3 percussion components per sticking contact, the normal percussion
  // per slipping contact (P = P_N (1, mu d)); as many equations (xi = 0 when sticking, xi_N = 0
  // when slipping). Newton on the slip angles, f_i = d_i x xi_T,i, with the analytic Jacobian.
  template <int K>
  bool SolveCase(const std::array<ContactStatus, 2>& status, std::array<Vector2d, 2> d,
                 Vector6d* p) const {
    using Basis = Eigen::Matrix<double, 6, K == 0 ? 1 : K>;
    using Square = Eigen::Matrix<double, K == 0 ? 1 : K, K == 0 ? 1 : K>;
    using Small = Eigen::Matrix<double, K == 0 ? 1 : K, 1>;
    int slips = 0;
    std::array<int, 2> slip_contact{}, slip_column{};
    std::array<int, 6> rows{};
    Basis basis = Basis::Zero();
    int k = 0;
    for (int i = 0; i < 2; ++i) {
      if (status[i] == ContactStatus::kSticking) {
        if (k + 3 > K) return false;
        for (int r = 0; r < 3; ++r) {
          basis(3 * i + r, k) = 1;
          rows[k++] = 3 * i + r;
        }
      } else if (status[i] == ContactStatus::kSlipping) {
        if (k + 1 > K) return false;
        slip_contact[slips] = i;
        slip_column[slips++] = k;
        rows[k++] = 3 * i;
      }
    }
    Vector6d x_full, xi;
    for (int iter = 0; iter < 30; ++iter) {
      Square inverse;
      Small x;
      Basis gb;
      if constexpr (K == 0) {
        x_full.setZero();
        xi = pr_.xi0;
      } else {
        for (int s = 0; s < slips; ++s) {
          const int i = slip_contact[s], col = slip_column[s];
          basis(3 * i, col) = 1;
          basis.template block<2, 1>(3 * i + 1, col) = pr_.mu[i] * d[i];
        }
        gb = pr_.g * basis;
        Square a;
        Small rhs;
        for (int r = 0; r < K; ++r) {
          a.row(r) = gb.row(rows[r]);
          rhs(r) = -pr_.xi0(rows[r]);
        }
        inverse = a.inverse();
        x = inverse * rhs;
        if (!x.allFinite()) return false;
        x_full = basis * x;
        xi = pr_.xi0 + gb * x;
      }
      // Residual: slip velocity normal to each slip direction.
      Vector2d f = Vector2d::Zero();
      double worst = 0;
      for (int s = 0; s < slips; ++s) {
        const int i = slip_contact[s];
        f(s) = pr_.mu[i] > 0 ? Cross(d[i], xi.segment<2>(3 * i + 1)) : 0.0;
        worst = std::max(worst, std::abs(f(s)));
      }
      if (worst <= 0.1 * tolerance_) {
        if (!Verify(pr_, status, d, x_full, xi, tolerance_)) return false;
        *p = x_full;
        return true;
      }
      if constexpr (K > 0) {
        // Jacobian of f with respect to the slip angles.
        Eigen::Matrix2d jac = Eigen::Matrix2d::Zero();
        for (int s = 0; s < slips; ++s) {
          const int j = slip_contact[s];
          const Vector2d perp(-d[j].y(), d[j].x());
          const Vector6d v = (pr_.g.col(3 * j + 1) * perp.x() + pr_.g.col(3 * j + 2) * perp.y()) *
                             (pr_.mu[j] * x(slip_column[s]));
          Small rv;
          for (int r = 0; r < K; ++r) rv(r) = v(rows[r]);
          const Vector6d dxi = v - gb * (inverse * rv);
          for (int q = 0; q < slips; ++q) {
            const int i = slip_contact[q];
            jac(q, s) = Cross(d[i], dxi.segment<2>(3 * i + 1));
            if (q == s) jac(q, s) -= d[i].dot(xi.segment<2>(3 * i + 1));
          }
        }
        for (int q = 0; q < slips; ++q) {
          if (pr_.mu[slip_contact[q]] > 0) continue;  // frictionless: no slip direction to find
          jac.row(q).setZero();
          jac(q, q) = 1;
        }
        Vector2d step;
        if (slips == 1) {
          if (!(jac(0, 0) != 0)) return false;
          step(0) = -f(0) / jac(0, 0);
        } else {
          const double det = jac.determinant();
          if (!(det != 0)) return false;
          step = -jac.inverse() * f;
        }
        for (int s = 0; s < slips; ++s) {
          if (!std::isfinite(step(s))) return false;
          const int i = slip_contact[s];
          const Vector2d perp(-d[i].y(), d[i].x());
          d[i] = (d[i] + std::clamp(step(s), -0.5, 0.5) * perp).normalized();
        }
      }
    }
    return false;
  }

  // Both sticking: xi = 0 at both contacts. G is singular along z, so the minimum-norm solution
  // of G P = -xi0 (exact when xi0 is in G's range) is moved along z, nearest to the guess's
  // internal force, into both friction cones.
  bool SolveBothSticking(const Vector6d& guess, Vector6d* p) const {
    const Vector6d& z = pr_.null;
    const Matrix6d regular = pr_.g + (pr_.g.trace() / 6) * z * z.transpose();
    Vector6d base = -regular.ldlt().solve(pr_.xi0);
    base -= z.dot(base) * z;
    const Vector6d xi = pr_.xi0 + pr_.g * base;
    if (!(xi.lpNorm<Eigen::Infinity>() <= 0.1 * tolerance_)) return false;
    double lo = -INFINITY, hi = INFINITY;
    for (int i = 0; i < 2; ++i) {
      double a, b;
      if (!ConeInterval(base.segment<3>(3 * i), z.segment<3>(3 * i), pr_.mu[i], &a, &b))
        return false;
      lo = std::max(lo, a);
      hi = std::min(hi, b);
    }
    if (!(lo <= hi)) return false;
    const Vector6d candidate = base + std::clamp(z.dot(guess), lo, hi) * z;
    const std::array<Vector2d, 2> unused{Vector2d::Zero(), Vector2d::Zero()};
    if (!Verify(pr_, {ContactStatus::kSticking, ContactStatus::kSticking}, unused, candidate,
                pr_.xi0 + pr_.g * candidate, tolerance_))
      return false;
    *p = candidate;
    return true;
  }

  const PairProblem& pr_;
  double tolerance_;
};

}  // namespace

bool SolvePair(const PairProblem& problem, const Vector6d& guess, double tolerance_m_s,
               Vector6d* p) {
  // The guessed case and its slip directions.
  std::array<ContactStatus, 2> guessed{};
  std::array<Vector2d, 2> d{};
  for (int i = 0; i < 2; ++i) {
    const Vector3d g = guess.segment<3>(3 * i);
    const double tangential = g.tail<2>().norm();
    if (!(g.x() > 0)) {
      guessed[i] = ContactStatus::kSeparated;
    } else if (tangential < problem.mu[i] * g.x() * (1 - 1e-6)) {
      guessed[i] = ContactStatus::kSticking;
    } else {
      guessed[i] = ContactStatus::kSlipping;
    }
    if (tangential > 0) {
      d[i] = g.tail<2>() / tangential;
    } else {
      // Opposite to the tangential velocity a frictionless impact at this contact alone leaves.
      const Matrix6d& gm = problem.g;
      const double a = gm(3 * i, 3 * i);
      Vector2d v = -(problem.xi0.segment<2>(3 * i + 1) -
                     (problem.xi0(3 * i) / a) * gm.block<2, 1>(3 * i + 1, 3 * i));
      d[i] = v.squaredNorm() > 0 ? Vector2d(v.normalized()) : Vector2d(1, 0);
    }
  }
  const PairCases cases(problem, tolerance_m_s);
  if (cases.Solve(guessed, d, guess, p)) return true;
  constexpr ContactStatus kSep = ContactStatus::kSeparated, kStick = ContactStatus::kSticking,
                          kSlip = ContactStatus::kSlipping;
  constexpr std::array<std::array<ContactStatus, 2>, 9> kOrder{{{kSep, kSep},
                                                                {kStick, kSep},
                                                                {kSep, kStick},
                                                                {kSlip, kSep},
                                                                {kSep, kSlip},
                                                                {kStick, kStick},
                                                                {kStick, kSlip},
                                                                {kSlip, kStick},
                                                                {kSlip, kSlip}}};
  for (const auto& status : kOrder) {
    if (status == guessed) continue;
    if (cases.Solve(status, d, guess, p)) return true;
  }
  // Slip Newton may have found the root with d along the slip (d x xi_T = 0 too): restart both
  // slipping cases from the slip directions of the frictionless solution of the pair.
  Eigen::Matrix2d normal;
  normal << problem.g(0, 0), problem.g(0, 3), problem.g(3, 0), problem.g(3, 3);
  const Vector2d pn = -normal.inverse() * Vector2d(problem.xi0(0), problem.xi0(3));
  const Vector6d xi = problem.xi0 + problem.g.col(0) * pn(0) + problem.g.col(3) * pn(1);
  std::array<Vector2d, 2> frictionless = d;
  for (int i = 0; i < 2; ++i) {
    const Vector2d slip = xi.segment<2>(3 * i + 1);
    if (slip.squaredNorm() > 0) frictionless[i] = -slip.normalized();
  }
  for (const auto& status :
       {std::array<ContactStatus, 2>{kSlip, kSlip}, std::array<ContactStatus, 2>{kStick, kSlip},
        std::array<ContactStatus, 2>{kSlip, kStick}})
    if (cases.Solve(status, frictionless, guess, p)) return true;
  return false;
}

double PairLawViolation(const PairProblem& problem, const Vector6d& p) {
  const Vector6d xi = problem.xi0 + problem.g * p;
  double worst = 0;
  for (int i = 0; i < 2; ++i) {
    const double gn = problem.g(3 * i, 3 * i);
    const Vector3d pi = p.segment<3>(3 * i), xii = xi.segment<3>(3 * i);
    // Natural-map residual of the proximal-point form of the laws, step 1 / G_NN, in m/s.
    const double normal = std::max(0.0, pi.x() - xii.x() / gn);
    const Vector2d tangential =
        ProjectDisk(pi.tail<2>() - xii.tail<2>() / gn, problem.mu[i] * normal);
    worst = std::max(worst, gn * std::abs(pi.x() - normal));
    worst = std::max(worst, gn * (pi.tail<2>() - tangential).norm());
  }
  return worst;
}

}  // namespace talus
