#include "calibration/optimizer.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <exception>
#include <sstream>
#include <stdexcept>

#include "calibration/designs.hpp"
#include "calibration/report_text.hpp"

namespace talus::calibration {

const std::vector<std::string>& AlgorithmNames() {
  static const std::vector<std::string> names = {"bobyqa",   "sbplx", "crs2_lm",
                                                 "direct_l", "isres", "ceres"};
  return names;
}

bool IsLocalAlgorithm(const std::string& name) {
  return name == "bobyqa" || name == "sbplx" || name == "ceres";
}

const char* ToString(Termination t) {
  switch (t) {
    case Termination::kConvergence:
      return "convergence";
    case Termination::kMaxEvaluations:
      return "max_evaluations";
    case Termination::kMaxTime:
      return "max_time";
    case Termination::kFailure:
      break;
  }
  return "failure";
}

bool OptimizerOptions::IsValid(std::string* why) const {
  std::ostringstream msg;
  const auto& names = AlgorithmNames();
  if (std::find(names.begin(), names.end(), algorithm) == names.end())
    msg << "algorithm = '" << algorithm
        << "' is not one of bobyqa, sbplx, crs2_lm, direct_l, isres, ceres";
  else if (max_evaluations < 1)
    msg << "max_evaluations = " << max_evaluations << " must be >= 1";
  else if (!(max_time_s >= 0) || !std::isfinite(max_time_s))
    msg << "max_time_s = " << max_time_s << " must be >= 0 (0: no limit)";
  else if (!(ftol_rel >= 0) || !(ftol_abs >= 0) || !(xtol_abs >= 0))
    msg << "tolerances must be >= 0 (ftol_rel = " << ftol_rel << ", ftol_abs = " << ftol_abs
        << ", xtol_abs = " << xtol_abs << ")";
  else if (!(initial_step > 0 && initial_step <= 1))
    msg << "initial_step = " << initial_step << " must be in (0, 1] (a fraction of the range)";
  else if (population < 0)
    msg << "population = " << population << " must be >= 0 (0: NLopt's default)";
  else if (starts < 1 || starts > max_evaluations)
    msg << "starts = " << starts << " must be in 1 .. max_evaluations = " << max_evaluations;
  else if (start_design != "sobol" && start_design != "lhs")
    msg << "start_design = '" << start_design << "' must be \"sobol\" or \"lhs\"";
  else if (!(fd_step >= 0 && fd_step <= 0.25))
    msg << "fd_step = " << fd_step << " must be in [0, 0.25] (0: measured)";
  if (msg.str().empty()) return true;
  if (why) *why = msg.str();
  return false;
}

std::vector<Eigen::VectorXd> StartPoints(const Objective& objective,
                                         const OptimizerOptions& options) {
  const int n = objective.dimension();
  if (options.start_design == "sobol" && options.starts > 1 && n > kMaxSobolDimension)
    throw std::invalid_argument("Optimize: Sobol starts for more than 16 parameters; use lhs");
  Eigen::VectorXd x0 = options.start ? *options.start : objective.StartPoint();
  if (x0.size() != n) throw std::invalid_argument("Optimize: start has the wrong dimension");
  std::vector<Eigen::VectorXd> starts = {x0.cwiseMax(0.0).cwiseMin(1.0)};
  if (options.starts > 1) {
    const Eigen::MatrixXd design = options.start_design == "sobol"
                                       ? Sobol(options.starts - 1, n, options.seed)
                                       : LatinHypercube(options.starts - 1, n, options.seed);
    for (int k = 0; k < design.rows(); ++k) starts.push_back(design.row(k).transpose());
  }
  return starts;
}

std::string OptimizerSummary::BriefReport() const {
  char line[512];
  std::snprintf(line, sizeof line,
                "%s %s: %s after %d evaluations in %.1f s; objective %s -> %s (%d starts)",
                algorithm == "ceres" ? "Ceres" : "NLopt", algorithm.c_str(), ToString(termination),
                evaluations(), wall_time_s, Num(initial.value).c_str(), Num(best.value).c_str(),
                static_cast<int>(starts.size()));
  return line;
}

std::string OptimizerSummary::FullReport() const {
  std::string out = "\nCalibration report\n";
  char line[512];
  std::snprintf(line, sizeof line,
                "  %-28s %s\n  %-28s %s\n  %-28s %d (%d asked again, %d from a checkpoint)\n",
                "Algorithm", algorithm.c_str(), "Termination", message.c_str(), "Evaluations",
                evaluations(), cache_hits, replayed);
  out += line;
  std::snprintf(line, sizeof line, "  %-28s %s\n  %-28s %s (data %s + prior %s)\n  %-28s %.2f s\n",
                "Initial objective", Num(initial.value).c_str(), "Final objective",
                Num(best.value).c_str(), Num(best.data).c_str(), Num(best.prior).c_str(),
                "Wall time", wall_time_s);
  out += line;
  std::snprintf(line, sizeof line, "\n  %-28s %14s %14s %10s\n", "parameter", "initial", "final",
                "final u");
  out += line;
  for (std::size_t j = 0; j < names.size(); ++j) {
    const auto k = static_cast<Eigen::Index>(j);
    std::snprintf(line, sizeof line, "  %-28s %14s %14s %10s\n", names[j].c_str(),
                  Num(initial.values.size() > k ? initial.values[k] : kNaN).c_str(),
                  Num(best.values.size() > k ? best.values[k] : kNaN).c_str(),
                  Num(best.u.size() > k ? best.u[k] : kNaN, "%.4f").c_str());
    out += line;
  }
  if (!std::isnan(fd_step)) {
    std::snprintf(line, sizeof line, "  %-28s %.3g (of each range)\n", "Finite-difference step",
                  fd_step);
    out += line;
  }
  if (!std::isnan(fd_shrink)) {
    std::snprintf(line, sizeof line,
                  "  %-28s noise-dominated: Gauss-Newton steps shortened to %.2g (more rocks per "
                  "run lower the noise)\n",
                  "Jacobian", fd_shrink);
    out += line;
  }
  out += "\n  start  evaluations  best objective  result\n";
  for (std::size_t s = 0; s < starts.size(); ++s) {
    std::snprintf(line, sizeof line, "  %5zu  %11d  %14s  %s\n", s, starts[s].evaluations,
                  Num(starts[s].best_value).c_str(), starts[s].result.c_str());
    out += line;
  }
  return out + BriefReport() + "\n";
}

}  // namespace talus::calibration
