#include "calibration/seeds.hpp"

#include <boost/math/distributions/normal.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <sstream>
#include <stdexcept>

#include "calibration/report_text.hpp"

namespace talus::calibration {
namespace {

// The standard normal quantile at p in (0, 1) (Boost.Math).
double NormalQuantile(double p) { return boost::math::quantile(boost::math::normal(), p); }

// One seed's refit: its objective, each lattice point evaluated once.
Eigen::VectorXd RefitWithSeed(const Objective& objective, std::uint64_t seed,
                              const std::vector<int>& free, const Eigen::VectorXd& origin,
                              const BootstrapOptions& refit, int budget, bool* at_budget,
                              int* evaluations) {
  std::map<std::vector<double>, double> values;
  const std::function<double(const Eigen::VectorXd&)> f = [&](const Eigen::VectorXd& u) {
    const std::vector<double> key(u.data(), u.data() + u.size());
    const auto it = values.find(key);
    if (it != values.end()) return it->second;
    ++*evaluations;
    return values[key] = objective.EvaluateWithSeed(u, seed).value;
  };
  return RefitFromOptimum(f, free, origin, refit, budget, at_budget);
}

// The seeds' spread, its small-S correction, and its combination with the bootstrap.
void Combine(const Objective& objective, const Bootstrap& bootstrap, SeedRefits& out) {
  const auto n = static_cast<Eigen::Index>(out.names.size());
  const double inflation = 1 + 1 / std::sqrt(2.0 * (out.seeds - 1));
  const double z = NormalQuantile((1 + out.level) / 2);
  const Eigen::VectorXd low = objective.parameters().Values(Eigen::VectorXd::Zero(n));
  const Eigen::VectorXd high = objective.parameters().Values(Eigen::VectorXd::Ones(n));
  out.fitted = objective.parameters().Values(bootstrap.u);
  for (Eigen::VectorXd* v :
       {&out.sd, &out.sd_unit, &out.seed_standard_error, &out.combined_standard_error,
        &out.combined_standard_error_unit, &out.lower, &out.upper})
    *v = Eigen::VectorXd::Constant(n, kNaN);
  for (Eigen::Index j = 0; j < n; ++j) {
    if (!out.identified[static_cast<std::size_t>(j)]) continue;
    out.sd[j] = SampleSd(out.refits.col(j));
    out.sd_unit[j] = SampleSd(out.refits_unit.col(j));
    out.seed_standard_error[j] = inflation * out.sd[j];
    out.combined_standard_error[j] =
        std::hypot(bootstrap.standard_error[j], out.seed_standard_error[j]);
    out.combined_standard_error_unit[j] =
        std::hypot(bootstrap.standard_error_unit[j], inflation * out.sd_unit[j]);
    // Each side of the bootstrap's percentile interval, widened by the seeds' in quadrature.
    const double below = std::max(0.0, out.fitted[j] - bootstrap.lower[j]);
    const double above = std::max(0.0, bootstrap.upper[j] - out.fitted[j]);
    const double seeds = z * out.seed_standard_error[j];
    const double a = std::min(low[j], high[j]), b = std::max(low[j], high[j]);
    out.lower[j] = std::clamp(out.fitted[j] - std::hypot(below, seeds), a, b);
    out.upper[j] = std::clamp(out.fitted[j] + std::hypot(above, seeds), a, b);
  }
}

}  // namespace

bool SeedRefitOptions::IsValid(std::string* why) const {
  if (seeds == 0 || (seeds >= 2 && seeds <= kMaxSeeds)) return true;
  if (why) {
    std::ostringstream msg;
    msg << "seeds = " << seeds << " must be 0 (off) or in 2 .. " << kMaxSeeds
        << " (refits with other release seeds; an sd needs 2)";
    *why = msg.str();
  }
  return false;
}

SeedRefits RefitWithOtherSeeds(const Objective& objective, const Bootstrap& bootstrap,
                               const BootstrapOptions& refit, const SeedRefitOptions& options) {
  std::string why;
  if (!options.IsValid(&why)) throw std::invalid_argument("RefitWithOtherSeeds: " + why);
  if (!refit.IsValid(&why)) throw std::invalid_argument("RefitWithOtherSeeds: " + why);
  const auto t0 = std::chrono::steady_clock::now();
  const int n = objective.dimension();
  SeedRefits out;
  out.seeds = options.seeds;
  out.level = bootstrap.level;
  out.names = bootstrap.names;
  out.identified = bootstrap.identified;
  std::vector<int> free;
  for (int j = 0; j < n; ++j)
    if (out.identified[static_cast<std::size_t>(j)]) free.push_back(j);
  const int budget = RefitBudget(refit, static_cast<int>(free.size()));
  out.refits_unit = bootstrap.u.transpose().replicate(options.seeds, 1);
  out.refits = Eigen::MatrixXd(options.seeds, n);
  for (int s = 0; s < options.seeds; ++s) {
    const std::uint64_t seed = objective.release().seed + static_cast<std::uint64_t>(s) + 1;
    out.release_seeds.push_back(seed);
    bool at_budget = false;
    if (!free.empty())
      out.refits_unit.row(s) = RefitWithSeed(objective, seed, free, bootstrap.u, refit, budget,
                                             &at_budget, &out.evaluations)
                                   .transpose();
    out.refits_at_budget += at_budget ? 1 : 0;
    out.refits.row(s) = objective.parameters().Values(out.refits_unit.row(s).transpose());
  }
  if (options.seeds > 0) Combine(objective, bootstrap, out);
  std::ostringstream note;
  if (options.seeds == 0)
    note << "no seed refits (seeds = 0).";
  else if (free.empty())
    note << "no seed refits: no parameter is refitted by the bootstrap.";
  else
    note << options.seeds << " refits with the release seeds " << out.release_seeds.front()
         << " .. " << out.release_seeds.back() << ", each by BOBYQA from the optimum (at most "
         << budget << " evaluations); standard error sqrt(bootstrap's^2 + (seeds' sd x "
         << Num(1 + 1 / std::sqrt(2.0 * (options.seeds - 1)), "%.3g") << ")^2)";
  if (options.seeds > 0 && !free.empty()) {
    if (out.refits_at_budget > 0) note << "; " << out.refits_at_budget << " ended at that budget";
    note << ".";
  }
  out.note = note.str();
  out.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

std::string SeedRefits::Report() const {
  std::string out = "Uncertainty (bootstrap and " + std::to_string(seeds) +
                    " refits with other seeds, " + std::to_string(evaluations) + " evaluations):\n";
  char line[256];
  char interval[32];
  std::snprintf(interval, sizeof interval, "%g %% interval", 100 * level);
  std::snprintf(line, sizeof line, "  %-28s %12s %14s  %s\n", "parameter", "seeds' sd",
                "combined s.e.", interval);
  out += line;
  for (std::size_t j = 0; j < names.size(); ++j) {
    const auto k = static_cast<Eigen::Index>(j);
    std::string range = "UNIDENTIFIED";
    if (identified[j]) {
      range = "[";
      range += Num(lower[k], "%.6g") + ", " + Num(upper[k], "%.6g") + "]";
    }
    std::snprintf(line, sizeof line, "  %-28s %12s %14s  %s\n", names[j].c_str(),
                  Num(sd[k], "%.4g").c_str(), Num(combined_standard_error[k], "%.4g").c_str(),
                  range.c_str());
    out += line;
  }
  return out + "  " + note + "\n";
}

}  // namespace talus::calibration
