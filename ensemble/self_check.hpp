#pragma once
// The discretisation self-check a run can ask for ([solver] self_check = N, talus simulate
// --self-check N): a deterministic subsample of N rocks run twice, with the scene's solver options
// and with a halved step and a tightened contact solve, and the difference of each headline
// statistic with its standard error (a paired bootstrap over the rocks), so that a run states
// whether its time step is converged for what hazard work reads from it.

#include <memory>
#include <string>
#include <vector>

#include "ensemble/evaluation_lines.hpp"
#include "ensemble/release.hpp"
#include "solver/scene.hpp"

namespace talus::ensemble {

struct SelfCheckOptions {
  long rocks = 0;   // subsample size: every (total / rocks)-th rock of the release, from rock 0
  int threads = 0;  // worker threads; 0: all cores
  // The refined run: dt_s / dt_divisor and the contact solve at refined_tolerance_m_s (or the
  // scene's, if tighter).
  int dt_divisor = 2;
  double refined_tolerance_m_s = 1e-7;
  int bootstrap_resamples = 400;  // paired resamples of the subsample for the standard errors
  // The chance that a converged run is reported biased, over all its statistics together: each
  // difference is significant beyond z standard errors with P(|Z| > z) = this / statistics
  // (Bonferroni; 2.58 for five statistics, 2.84 for nine).
  double false_alarm_rate = 0.05;
  // Evaluation lines whose energy p95 is compared too; null or empty: none.
  std::shared_ptr<const std::vector<EvaluationLine>> evaluation_lines;
  bool IsValid(std::string* why) const;
};

// One headline statistic over the subsample, at the scene's step and at the refined one.
struct SelfCheckStatistic {
  std::string name;  // e.g. "run-out p95"
  std::string unit;  // e.g. "m"
  double as_run = 0, refined = 0;
  double difference = 0;      // as_run - refined
  double standard_error = 0;  // of the difference, paired bootstrap
  bool significant = false;   // |difference| > SelfCheckReport::threshold x standard_error
};

struct SelfCheckReport {
  long rocks = 0;  // in the subsample
  double dt_s = 0, refined_dt_s = 0;
  double tolerance_m_s = 0, refined_tolerance_m_s = 0;
  double threshold = 0;  // standard errors beyond which a difference is significant
  std::vector<SelfCheckStatistic> statistics;
  bool converged = true;  // no statistic differs significantly
  double wall_time_s = 0;
  // "converged within the sampling noise (N rocks at dt and dt/2)", or the largest significant
  // bias and the advice to use --preset accurate.
  std::string Verdict() const;
  std::string BriefReport() const;  // the verdict and one line per statistic
};

// Runs the self-check of `scene` (whose options are those of the run being checked) and
// `release`. The scene's solver options are changed for the refined run and restored before
// returning (the scene is not copied: its terrain may be large). Requires a valid scene, release
// and options, and options.rocks <= release.total_rocks().
SelfCheckReport RunSelfCheck(Scene& scene, const ReleaseSpec& release,
                             const SelfCheckOptions& options);

}  // namespace talus::ensemble
