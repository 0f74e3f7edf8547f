#include "calibration/bootstrap.hpp"

#include <nlopt.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <functional>
#include <map>
#include <random>
#include <sstream>
#include <stdexcept>

#include "calibration/report_text.hpp"
#include "common/statistics.hpp"

namespace talus::calibration {
namespace {

// What one evaluation contributes to every resample's objective.
struct GroupScores {
  bool feasible = true;
  double value = kNaN;   // the objective (the penalty when infeasible)
  Eigen::VectorXd sums;  // per group: the sum of its squared residuals
  double prior = 0;      // the prior's residuals (no group), squared and summed
};

GroupScores GroupScoresOf(const Evaluation& e, const std::vector<int>& groups, int group_count) {
  GroupScores s;
  s.feasible = e.feasible;
  s.value = e.value;
  s.sums = Eigen::VectorXd::Zero(group_count);
  for (Eigen::Index i = 0; i < e.residuals.size(); ++i) {
    const int g = groups[static_cast<std::size_t>(i)];
    (g >= 0 ? s.sums[g] : s.prior) += e.residuals[i] * e.residuals[i];
  }
  return s;
}

// The objective's evaluations by their exact point, shared by every resample's refit.
class GroupScoreCache {
 public:
  GroupScoreCache(const Objective& objective, const std::vector<Evaluation>& known)
      : objective_(objective) {
    for (const Evaluation& e : known) Add(e);
  }

  const GroupScores& At(const Eigen::VectorXd& u) {
    const auto it = scores_.find(Key(u));
    if (it != scores_.end()) {
      ++cached_;
      return it->second;
    }
    ++evaluations_;
    return Add(objective_.Evaluate(u));
  }
  int evaluations() const { return evaluations_; }
  int cached() const { return cached_; }

 private:
  static std::vector<double> Key(const Eigen::VectorXd& u) {
    return std::vector<double>(u.data(), u.data() + u.size());
  }
  const GroupScores& Add(const Evaluation& e) {
    const std::vector<int>& groups = objective_.residual_groups();
    int count = 0;
    for (int g : groups) count = std::max(count, g + 1);
    return scores_[Key(e.u)] = GroupScoresOf(e, groups, count);
  }

  const Objective& objective_;
  std::map<std::vector<double>, GroupScores> scores_;
  int evaluations_ = 0, cached_ = 0;
};

// One refit: NLopt's callback state.
struct Refit {
  const std::function<double(const Eigen::VectorXd&)>& f;
  const std::vector<int>& free;   // refitted coordinates
  const Eigen::VectorXd& origin;  // the optimum: the lattice's origin
  double resolution;              // the lattice's spacing; 0: none
  Eigen::VectorXd u;              // the full point (held coordinates at the optimum)
  std::exception_ptr error;
  nlopt_opt opt = nullptr;
};

// x rounded to the nearest point of the lattice origin + resolution k, inside [0, 1].
double OnLattice(double x, double origin, double resolution) {
  if (!(resolution > 0)) return x;
  return std::clamp(origin + resolution * std::round((x - origin) / resolution), 0.0, 1.0);
}

double RefitObjective(unsigned /*n*/, const double* x, double* /*grad*/, void* data) {
  Refit& r = *static_cast<Refit*>(data);
  for (std::size_t k = 0; k < r.free.size(); ++k)
    r.u[r.free[k]] = OnLattice(x[k], r.origin[r.free[k]], r.resolution);
  try {
    return r.f(r.u);
  } catch (...) {
    r.error = std::current_exception();
    nlopt_force_stop(r.opt);
    return HUGE_VAL;
  }
}

// Standard errors, intervals and correlations from the refits.
void Summarise(Bootstrap& out) {
  const int n = static_cast<int>(out.names.size());
  out.standard_error = Eigen::VectorXd::Constant(n, kNaN);
  out.standard_error_unit = Eigen::VectorXd::Constant(n, kNaN);
  out.lower = Eigen::VectorXd::Constant(n, kNaN);
  out.upper = Eigen::VectorXd::Constant(n, kNaN);
  out.correlation = Eigen::MatrixXd::Constant(n, n, kNaN);
  for (int j = 0; j < n; ++j) {
    if (!out.identified[static_cast<std::size_t>(j)]) continue;
    out.standard_error[j] = SampleSd(out.refits.col(j));
    out.standard_error_unit[j] = SampleSd(out.refits_unit.col(j));
    std::vector<double> sorted(out.refits.col(j).data(),
                               out.refits.col(j).data() + out.refits.rows());
    std::sort(sorted.begin(), sorted.end());
    out.lower[j] = SortedQuantile(sorted, (1 - out.level) / 2);
    out.upper[j] = SortedQuantile(sorted, (1 + out.level) / 2);
  }
  for (int j = 0; j < n; ++j)
    for (int k = 0; k < n; ++k) {
      if (!out.identified[static_cast<std::size_t>(j)] ||
          !out.identified[static_cast<std::size_t>(k)])
        continue;
      const Eigen::ArrayXd a = out.refits_unit.col(j).array() - out.refits_unit.col(j).mean();
      const Eigen::ArrayXd b = out.refits_unit.col(k).array() - out.refits_unit.col(k).mean();
      const double norm = std::sqrt(a.square().sum() * b.square().sum());
      out.correlation(j, k) = norm > 0 ? (a * b).sum() / norm : kNaN;
    }
}

}  // namespace

double SampleSd(const Eigen::VectorXd& x) {
  const double mean = x.mean();
  return std::sqrt((x.array() - mean).square().sum() / double(x.size() - 1));
}

int RefitBudget(const BootstrapOptions& options, int refitted) {
  return options.refit_evaluations > 0 ? options.refit_evaluations : 10 * (refitted + 2);
}

Eigen::VectorXd RefitFromOptimum(const std::function<double(const Eigen::VectorXd&)>& f,
                                 const std::vector<int>& free, const Eigen::VectorXd& origin,
                                 const BootstrapOptions& options, int budget, bool* at_budget,
                                 const Eigen::VectorXd* start) {
  const auto k = free.size();
  const std::vector<double> lower(k, 0.0), upper(k, 1.0);
  // Steps below half the lattice spacing would ask for the same point again.
  const std::vector<double> step(k, std::max(options.initial_step, options.resolution));
  const std::vector<double> xtol(k, std::max(options.xtol_abs, options.resolution / 2));
  Refit refit{f, free, origin, options.resolution, origin, nullptr, nullptr};
  refit.opt = nlopt_create(NLOPT_LN_BOBYQA, static_cast<unsigned>(k));
  if (!refit.opt) throw std::runtime_error("RefitFromOptimum: NLopt could not start");
  nlopt_set_min_objective(refit.opt, RefitObjective, &refit);
  nlopt_set_lower_bounds(refit.opt, lower.data());
  nlopt_set_upper_bounds(refit.opt, upper.data());
  nlopt_set_initial_step(refit.opt, step.data());
  nlopt_set_xtol_abs(refit.opt, xtol.data());
  nlopt_set_ftol_rel(refit.opt, options.ftol_rel);
  nlopt_set_maxeval(refit.opt, budget);
  std::vector<double> x(k);
  for (std::size_t q = 0; q < k; ++q) x[q] = (start ? *start : origin)[free[q]];
  double value = 0;
  const nlopt_result result = nlopt_optimize(refit.opt, x.data(), &value);
  nlopt_destroy(refit.opt);
  if (refit.error) std::rethrow_exception(refit.error);
  *at_budget = result == NLOPT_MAXEVAL_REACHED;
  Eigen::VectorXd u = origin;
  for (std::size_t q = 0; q < k; ++q)
    u[free[q]] = OnLattice(x[q], origin[free[q]], options.resolution);
  return u;
}

bool BootstrapOptions::IsValid(std::string* why) const {
  std::ostringstream msg;
  if (resamples != 0 && (resamples < 10 || resamples > kMaxResamples))
    msg << "bootstrap = " << resamples << " must be 0 (off) or in 10 .. " << kMaxResamples
        << " (resamples, each a refit)";
  else if (refit_evaluations < 0)
    msg << "bootstrap_evaluations = " << refit_evaluations << " must be >= 0 (0: 10 (n + 2))";
  else if (!(initial_step > 0 && initial_step <= 1))
    msg << "bootstrap_initial_step = " << initial_step << " must be in (0, 1]";
  else if (!(resolution >= 0 && resolution <= 0.25))
    msg << "bootstrap_resolution = " << resolution << " must be in [0, 0.25] (0: exact points)";
  else if (!(xtol_abs >= 0) || !(ftol_rel >= 0))
    msg << "bootstrap tolerances must be >= 0";
  else if (!(start_spread >= 0 && start_spread <= 0.5))
    msg << "bootstrap_start_spread = " << start_spread << " must be in [0, 0.5]";
  else if (!(level > 0 && level < 1))
    msg << "bootstrap_level = " << level << " must be in (0, 1)";
  if (msg.str().empty()) return true;
  if (why) *why = msg.str();
  return false;
}

Eigen::MatrixXi ResampleCounts(int resamples, int groups, std::uint64_t seed) {
  Eigen::MatrixXi counts = Eigen::MatrixXi::Zero(resamples, groups);
  if (groups <= 0) return counts;
  // std::mt19937_64 is specified bit for bit; the draw is by rejection (no modulo bias), so the
  // counts are the same on every platform.
  std::mt19937_64 random(seed);
  const std::uint64_t g = static_cast<std::uint64_t>(groups);
  const std::uint64_t limit = std::mt19937_64::max() - std::mt19937_64::max() % g;
  for (int b = 0; b < resamples; ++b)
    for (int k = 0; k < groups; ++k) {
      std::uint64_t draw = random();
      while (draw >= limit) draw = random();
      ++counts(b, static_cast<Eigen::Index>(draw % g));
    }
  return counts;
}

Bootstrap BootstrapOverRuns(const Objective& objective, const Eigen::VectorXd& u,
                            const BootstrapOptions& options, const std::vector<Evaluation>& known) {
  std::string why;
  if (!options.IsValid(&why)) throw std::invalid_argument("BootstrapOverRuns: " + why);
  const auto t0 = std::chrono::steady_clock::now();
  const int n = objective.dimension();
  Bootstrap out;
  out.resamples = options.resamples;
  out.level = options.level;
  out.resolution = options.resolution;
  out.start_spread = options.start_spread;
  out.seed = options.seed;
  out.u = u.cwiseMax(0.0).cwiseMin(1.0);
  for (const Coordinate& c : objective.parameters().coordinates()) out.names.push_back(c.name);
  out.identified.assign(static_cast<std::size_t>(n), true);
  if (static_cast<int>(options.profiles.size()) == n)
    for (int j = 0; j < n; ++j)
      out.identified[static_cast<std::size_t>(j)] =
          options.profiles[static_cast<std::size_t>(j)].identified;
  std::vector<int> free;
  for (int j = 0; j < n; ++j)
    if (out.identified[static_cast<std::size_t>(j)]) free.push_back(j);
  for (int g : objective.residual_groups()) out.groups = std::max(out.groups, g + 1);

  const int k = static_cast<int>(free.size());
  const int budget = RefitBudget(options, k);
  const Eigen::MatrixXi counts = ResampleCounts(options.resamples, out.groups, options.seed);
  out.refits_unit = out.u.transpose().replicate(options.resamples, 1);
  GroupScoreCache cache(objective, known);
  if (k > 0 && out.groups > 1)
    for (int b = 0; b < options.resamples; ++b) {
      const Eigen::VectorXd weights = counts.row(b).transpose().cast<double>();
      const std::function<double(const Eigen::VectorXd&)> resampled =
          [&](const Eigen::VectorXd& v) {
            const GroupScores& s = cache.At(v);
            return s.feasible ? weights.dot(s.sums) + s.prior : s.value;
          };
      bool at_budget = false;
      Eigen::VectorXd start = out.u;
      if (options.start_spread > 0) {
        // Uniform draws on [-1, 1) from 53 bits of a generator of the resample's own.
        std::mt19937_64 draw(options.seed * 0x9E3779B97F4A7C15ULL + static_cast<std::uint64_t>(b));
        for (int j : free)
          start[j] = std::clamp(
              OnLattice(out.u[j] + options.start_spread * (2 * double(draw() >> 11) * 0x1p-53 - 1),
                        out.u[j], options.resolution),
              0.0, 1.0);
      }
      out.refits_unit.row(b) =
          RefitFromOptimum(resampled, free, out.u, options, budget, &at_budget, &start)
              .transpose();
      out.refits_at_budget += at_budget ? 1 : 0;
    }
  out.refits = Eigen::MatrixXd(options.resamples, n);
  for (int b = 0; b < options.resamples; ++b)
    out.refits.row(b) = objective.parameters().Values(out.refits_unit.row(b).transpose());
  out.evaluations = cache.evaluations();
  out.cached = cache.cached();

  if (k == 0)
    out.note = "no bootstrap: no parameter is identified.";
  else if (out.groups <= 1)
    out.note = "no bootstrap: one group of observations cannot be resampled.";
  if (k == 0 || out.groups <= 1) {
    out.identified.assign(static_cast<std::size_t>(n), false);
    out.refits_unit.setConstant(kNaN);
    out.refits.setConstant(kNaN);
  }
  Summarise(out);
  if (out.note.empty()) {
    std::ostringstream note;
    note << options.resamples << " resamples of " << out.groups << " runs, each refitted by BOBYQA"
         << (options.start_spread > 0 ? " from a start within +- " : " from the optimum");
    if (options.start_spread > 0) note << options.start_spread << " of each range of the optimum";
    note << " (at most " << budget << " evaluations";
    if (options.resolution > 0)
      note << ", on a lattice of " << options.resolution << " of each range";
    note << ")";
    if (out.refits_at_budget > 0) note << "; " << out.refits_at_budget << " ended at that budget";
    note << ".";
    out.note = note.str();
  }
  out.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

std::string Bootstrap::Report() const {
  std::string out = "Uncertainty (bootstrap over runs, " + std::to_string(resamples) +
                    " resamples, " + std::to_string(evaluations) + " evaluations, " +
                    std::to_string(cached) + " from the cache):\n";
  char line[256];
  char interval[32];
  std::snprintf(interval, sizeof interval, "%g %% interval", 100 * level);
  std::snprintf(line, sizeof line, "  %-28s %14s %10s  %s\n", "parameter", "std. error",
                "(of range)", interval);
  out += line;
  for (std::size_t j = 0; j < names.size(); ++j) {
    const auto k = static_cast<Eigen::Index>(j);
    // Appended piecewise: GCC 12 warns falsely (-Wrestrict) on "[" + std::string.
    std::string range = "[";
    range += Num(lower[k], "%.6g");
    range += ", ";
    range += Num(upper[k], "%.6g");
    range += "]";
    std::snprintf(line, sizeof line, "  %-28s %14s %10s  %s\n", names[j].c_str(),
                  Num(standard_error[k], "%.4g").c_str(),
                  Num(standard_error_unit[k], "%.3f").c_str(),
                  identified[j] ? range.c_str() : "UNIDENTIFIED");
    out += line;
  }
  if (names.size() > 1) {
    out += "  correlations:\n";
    for (Eigen::Index j = 0; j < correlation.rows(); ++j) {
      out += "    ";
      for (Eigen::Index k = 0; k < correlation.cols(); ++k)
        out += Num(correlation(j, k), "%6.2f") + " ";
      out += "\n";
    }
  }
  return out + "  " + note + "\n";
}

}  // namespace talus::calibration
