#include "calibration/roughness.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <sstream>

namespace talus::calibration {

bool RoughnessOptions::IsValid(std::string* why) const {
  std::ostringstream msg;
  if (steps.empty()) msg << "steps: give at least one step";
  for (double h : steps)
    if (msg.str().empty() && !(h > 0 && h <= 0.5))
      msg << "steps: " << h << " must be in (0, 0.5] (a fraction of the range)";
  if (msg.str().empty() && (seeds < 0 || seeds > 100))
    msg << "seeds = " << seeds << " must be in 0 .. 100";
  if (msg.str().empty() && !(signal_to_noise >= 1))
    msg << "signal_to_noise = " << signal_to_noise << " must be >= 1";
  if (msg.str().empty()) return true;
  if (why) *why = msg.str();
  return false;
}

RoughnessReport MeasureRoughness(const Objective& objective, const Eigen::VectorXd& u,
                                 const RoughnessOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  RoughnessReport r;
  r.steps = options.steps;
  std::sort(r.steps.begin(), r.steps.end());
  r.value = objective.Evaluate(u).value;
  ++r.evaluations;
  for (double h : r.steps) {
    std::vector<double> row;
    for (int j = 0; j < objective.dimension(); ++j) {
      Eigen::VectorXd v = u;
      v[j] += (v[j] + h <= 1) ? h : -h;
      row.push_back(std::abs(objective.Evaluate(v).value - r.value));
      ++r.evaluations;
    }
    r.change.push_back(row);
  }
  r.noise = *std::max_element(r.change.front().begin(), r.change.front().end());
  for (int s = 1; s <= options.seeds; ++s) {
    r.seed_values.push_back(objective.EvaluateWithSeed(u, objective.release().seed + s).value);
    ++r.evaluations;
  }
  if (!r.seed_values.empty()) {
    std::vector<double> all = r.seed_values;
    all.push_back(r.value);
    double mean = 0;
    for (double v : all) mean += v;
    mean /= double(all.size());
    double ss = 0;
    for (double v : all) ss += (v - mean) * (v - mean);
    r.seed_sd = std::sqrt(ss / double(all.size() - 1));
  }
  // The smallest step whose median change is signal_to_noise x the noise.
  r.fd_step = r.steps.back();
  for (std::size_t s = 0; s < r.steps.size(); ++s) {
    std::vector<double> row = r.change[s];
    std::nth_element(row.begin(), row.begin() + row.size() / 2, row.end());
    if (row[row.size() / 2] >= options.signal_to_noise * r.noise && row[row.size() / 2] > 0) {
      r.fd_step = r.steps[s];
      break;
    }
  }
  r.ftol_abs = 2 * r.noise;
  r.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

std::string RoughnessReport::Report() const {
  std::string out;
  char line[256];
  std::snprintf(line, sizeof line, "Roughness at f = %.6g (%d evaluations, %.1f s):\n", value,
                evaluations, wall_time_s);
  out += line;
  for (std::size_t s = 0; s < steps.size(); ++s) {
    std::snprintf(line, sizeof line, "  step %-8.2g |df| max %-10.3g median %.3g\n", steps[s],
                  *std::max_element(change[s].begin(), change[s].end()), [&] {
                    std::vector<double> row = change[s];
                    std::nth_element(row.begin(), row.begin() + row.size() / 2, row.end());
                    return row[row.size() / 2];
                  }());
    out += line;
  }
  std::snprintf(line, sizeof line,
                "  noise (largest |df| at the smallest step) %.3g; sd over %zu other seeds %.3g; "
                "finite-difference step %.2g; ftol_abs %.3g\n",
                noise, seed_values.size(), seed_sd, fd_step, ftol_abs);
  return out + line;
}

std::vector<ParameterProfile> ProfileParameters(const Objective& objective,
                                                const Eigen::VectorXd& u, double f_u, double noise,
                                                const ProfileOptions& options) {
  std::vector<ParameterProfile> out;
  const int points = std::max(2, options.points);
  for (int j = 0; j < objective.dimension(); ++j) {
    ParameterProfile p;
    p.name = objective.parameters().coordinates()[j].name;
    // Identified by the observations: the range of the data term, not of a prior's.
    const double data_u = f_u - objective.PriorTerm(u);
    double lo = data_u, hi = lo;
    int spanned = 1;  // the values the range spans: f(u)'s and each feasible point's
    for (int k = 0; k < points; ++k) {
      Eigen::VectorXd v = u;
      v[j] = double(k) / (points - 1);
      const Evaluation e = objective.Evaluate(v);
      p.u.push_back(v[j]);
      p.values.push_back(e.values[j]);
      p.f.push_back(e.value);
      if (!e.feasible) continue;  // a crossing of mu_min and mu_max is not information
      lo = std::min(lo, e.data);
      hi = std::max(hi, e.data);
      if (v[j] != u[j]) ++spanned;  // at u itself the same rocks give the same value again
    }
    p.range = hi - lo;
    // Above a few times the noise, and above what the noise alone spans over these values (more
    // than 3 x from about 10 of them on): a range within that may be all noise.
    const double noise_only = NoiseOnlyRange(spanned, noise);
    const double noise_threshold = std::max(options.noise_multiple * noise, noise_only);
    p.threshold = std::max(noise_threshold, options.relative_floor * std::abs(data_u));
    p.identified = p.range > p.threshold;
    if (noise > 0 && p.threshold == noise_threshold) {
      p.rocks_to_identify = RocksToIdentify(
          p.range, p.threshold, static_cast<double>(objective.release().rocks_per_release));
      p.within_noise = p.range <= noise_only;
    }
    out.push_back(p);
  }
  return out;
}

double RocksToIdentify(double range, double threshold, double rocks_per_run) {
  if (!(range > 0 && threshold > 0 && rocks_per_run > 0)) return kNaN;
  const double ratio = threshold / range;
  return rocks_per_run * ratio * ratio;
}

double NoiseOnlyRange(int points, double sd) {
  if (points < 2) return 0;
  // d2(n) = E[max - min of n standard normal draws] = integral over x of
  // 1 - Phi(x)^n - (1 - Phi(x))^n (Tippett 1925), by the trapezoid rule on [-12, 12], where the
  // integrand of any n below 10^6 has fallen under 1e-25.
  constexpr int kIntervals = 4800;
  constexpr double kHalfWidth = 12;
  const double h = 2 * kHalfWidth / kIntervals;
  double d2 = 0;
  for (int k = 0; k <= kIntervals; ++k) {
    const double x = -kHalfWidth + k * h;
    const double phi = 0.5 * std::erfc(-x / std::sqrt(2.0));
    const double f = 1 - std::pow(phi, points) - std::pow(1 - phi, points);
    d2 += (k == 0 || k == kIntervals ? 0.5 : 1) * f;
  }
  return d2 * h * sd;
}

}  // namespace talus::calibration
