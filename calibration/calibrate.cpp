#include "calibration/calibrate.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <utility>

#include "calibration/least_squares.hpp"
#include "common/error.hpp"

namespace talus::calibration {
namespace {

// printf into a string (the stages' lines for people), whatever its length.
template <class... Args>
std::string Format(const char* format, Args... args) {
  const int length = std::snprintf(nullptr, 0, format, args...);
  std::string line(static_cast<std::size_t>(std::max(length, 0)), '\0');
  std::snprintf(line.data(), line.size() + 1, format, args...);
  return line;
}

// What the rocks-per-run rule (RocksToIdentify) says of a profile, for people; "" when it says
// nothing.
std::string RocksHint(const ParameterProfile& p) {
  if (!std::isfinite(p.rocks_to_identify)) return "";
  const double rocks = std::max(2.0, std::ceil(p.rocks_to_identify));  // a run has >= 2 rocks
  if (p.identified) return Format(" (from about %.0f rocks per run on)", rocks);
  if (rocks > kMostRocksPerRun)
    return Format("; no practical number of rocks per run would (its range is %.2g of its "
                  "threshold)",
                  p.range / p.threshold);
  const std::string would =
      Format("; about %.0f rocks per run would (the noise falls as 1/sqrt(rocks))", rocks);
  if (p.within_noise)
    return would +
           " if its range is real: it is within what noise alone spans, and a range of "
           "noise falls with the rocks";
  return would;
}

std::string ProfilesReport(const std::vector<ParameterProfile>& profiles) {
  std::string out;
  for (const ParameterProfile& p : profiles)
    out +=
        Format("  %-28s profile range %-10.3g threshold %-10.3g %s%s\n", p.name.c_str(), p.range,
               p.threshold,
               p.identified ? "identified" : "UNIDENTIFIED: the observations do not constrain it",
               RocksHint(p).c_str());
  return out;
}

std::string CrossValidatedReport(std::size_t folds, const std::vector<HeldOutKind>& kinds) {
  HeldOutScores pooled;
  pooled.kinds = kinds;
  return Format("Cross-validated (%zu folds), every run scored by the fit without it:\n", folds) +
         pooled.Report();
}

bool BudgetEnded(const OptimizerSummary& s) {
  return s.termination == Termination::kMaxEvaluations || s.termination == Termination::kMaxTime;
}

// The stages of one calibration, sharing the problem, the options and the summary they fill.
class Pipeline {
 public:
  Pipeline(const CalibrationProblem& problem, const CalibrationOptions& options,
           CalibrationSummary& run)
      : problem_(problem), objective_(problem.objective()), options_(options), run_(run) {}

  void Fit();
  void Roughness();
  void Uncertainty();
  void ScoreBeforeAndAfter();
  void HoldOut();
  void CrossValidate();

 private:
  void Say(const std::string& text) const {
    if (options_.on_progress) options_.on_progress(text);
  }
  OptimizerSummary Optimise(const Objective& objective, const std::string& stage) const;
  // Scores `runs` at unit vector u of `objective` (its ground table and, with shape parameters,
  // its blocks), and with the reference table on the scene's own blocks.
  HeldOutScores Score(const RunSubset& runs, const Objective& objective, const Eigen::VectorXd& u,
                      const GroundTable* reference) const {
    // Every scoring runs the scene as the objective does (its contact-solve tolerance).
    std::vector<ensemble::Block> blocks;
    if (objective.parameters().has_shapes()) {
      try {
        blocks = objective.BlocksOf(u);
      } catch (const InputError&) {
        // Shapes that cannot be made (an infeasible start): nothing to score there.
        HeldOutScores none;
        for (const ensemble::ReleaseRun& r : runs.release.runs) none.runs.push_back(r.id);
        return none;
      }
    }
    return ScoreRuns(objective_.scene(), runs, objective.GroundOf(u), reference,
                     objective_.options().threads, objective_.needs_episodes(),
                     objective_.options().run_ensemble,
                     objective.parameters().has_shapes() ? &blocks : nullptr);
  }
  const GroundTable* reference() const {
    return problem_.reference() ? &*problem_.reference() : nullptr;
  }

  const CalibrationProblem& problem_;
  const Objective& objective_;
  const CalibrationOptions& options_;
  CalibrationSummary& run_;
};

// One optimisation, its evaluations replayed from and reported to the caller by stage.
OptimizerSummary Pipeline::Optimise(const Objective& objective, const std::string& stage) const {
  OptimizerOptions optimizer = options_.optimizer;
  if (const auto replay = options_.replay.find(stage); replay != options_.replay.end())
    optimizer.replay = replay->second;
  if (options_.on_evaluation)
    optimizer.on_evaluation = [this, stage](const Evaluation& e, int index) {
      options_.on_evaluation(stage, e, index);
    };
  if (options_.on_optimization_begins) options_.on_optimization_begins(stage);
  OptimizerSummary summary = Optimize(objective, optimizer);
  if (options_.on_optimization_ends) options_.on_optimization_ends(stage);
  return summary;
}

void Pipeline::Fit() {
  run_.fit = Optimise(objective_, "fit");
  Say(run_.fit.FullReport());
  if (!run_.fit.IsSolutionUsable()) throw std::runtime_error(run_.fit.message);
  run_.fitted = objective_.GroundOf(run_.fit.best.u);
  if (objective_.parameters().has_shapes()) run_.fitted_blocks = objective_.BlocksOf(run_.fit.best.u);
}

void Pipeline::Roughness() {
  if (!options_.roughness) return;
  const Evaluation& best = run_.fit.best;
  Say("Measuring the roughness and the profiles at the optimum...\n");
  run_.roughness = MeasureRoughness(objective_, best.u, options_.roughness_options);
  const auto t1 = std::chrono::steady_clock::now();
  run_.profiles = ProfileParameters(objective_, best.u, best.value, run_.roughness->level(),
                                    options_.profile_options);
  // The report's count and time are of both: the roughness' evaluations and the profiles'.
  run_.roughness->wall_time_s +=
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
  for (const ParameterProfile& p : run_.profiles)
    run_.roughness->evaluations += static_cast<int>(p.u.size());
  // The rocks-per-run rule holds for sampling noise only (docs/calibration.md).
  std::string rule;
  if (!run_.roughness->LevelIsSamplingNoise()) {
    for (ParameterProfile& p : run_.profiles) p.rocks_to_identify = kNaN;
    rule = Format(
        "  rocks per run to identify: not estimated: at the roughness' smallest step, %.2g, the "
        "objective's smooth change is part of it, and more rocks do not lower that; add a step "
        "of 1e-4 to [roughness] steps\n",
        run_.roughness->steps.front());
  }
  Say(run_.roughness->Report() + ProfilesReport(run_.profiles) + rule);
}

void Pipeline::Uncertainty() {
  if (!options_.uncertainty) return;
  const Evaluation& best = run_.fit.best;
  UncertaintyOptions uncertainty = options_.uncertainty_options;
  // The bootstrap's lattice: the fit's step, else the roughness'.
  const double lattice = run_.fit.fd_step > 0 ? run_.fit.fd_step
                         : run_.roughness     ? run_.roughness->fd_step
                                              : 0.01;
  if (!(uncertainty.fd_step > 0)) {
    Say("Choosing the covariance's finite-difference step at the optimum...\n");
    Say(ChooseCovarianceStep(objective_, best.u, uncertainty));
  }
  uncertainty.noise = run_.roughness ? run_.roughness->level() : 0;
  uncertainty.profiles = run_.profiles;
  Say("Estimating the covariance at the optimum...\n");
  run_.uncertainty = EstimateUncertainty(objective_, best.u, uncertainty, run_.fit.history);
  Say(run_.uncertainty->Report());
  if (options_.bootstrap_options.resamples <= 0) return;
  BootstrapOptions bootstrap = options_.bootstrap_options;
  bootstrap.resolution = options_.bootstrap_resolution.value_or(lattice);
  bootstrap.profiles = run_.profiles;
  Say(Format("Bootstrap over runs: %d resamples, each refitted...\n", bootstrap.resamples));
  run_.bootstrap = BootstrapOverRuns(objective_, best.u, bootstrap, run_.fit.history);
  Say(run_.bootstrap->Report());
  if (options_.seed_options.seeds <= 0) return;
  Say(Format("Refits with %d other release seeds...\n", options_.seed_options.seeds));
  run_.seeds = RefitWithOtherSeeds(objective_, *run_.bootstrap, bootstrap, options_.seed_options);
  Say(run_.seeds->Report());
}

void Pipeline::ScoreBeforeAndAfter() {
  Say("Scoring the observations before and after for the plots...\n");
  run_.before = Score(problem_.fitted_runs(), objective_, run_.fit.initial.u, nullptr);
  run_.after = Score(problem_.fitted_runs(), objective_, run_.fit.best.u, nullptr);
}

void Pipeline::HoldOut() {
  if (problem_.holdout().empty()) return;
  Say(Format("Scoring the %zu held-out runs...\n", problem_.holdout().size()));
  run_.holdout = Score(problem_.HeldOutRuns(), objective_, run_.fit.best.u, reference());
  Say(run_.holdout->Report());
}

void Pipeline::CrossValidate() {
  const auto& folds = problem_.folds();
  for (std::size_t f = 0; f < folds.size(); ++f) {
    Say(Format("Cross-validation: fold %zu of %zu (%zu runs held out)\n", f + 1, folds.size(),
               folds[f].size()));
    const Objective objective = problem_.ObjectiveOn(problem_.FoldTraining(static_cast<int>(f)));
    FoldRun fold;
    fold.summary = Optimise(objective, "fold" + std::to_string(f + 1));
    Say(fold.summary.BriefReport() + "\n");
    if (!fold.summary.IsSolutionUsable())
      throw std::runtime_error("fold " + std::to_string(f + 1) + ": " + fold.summary.message);
    fold.scores = Score(problem_.FoldRuns(static_cast<int>(f)), objective, fold.summary.best.u,
                        reference());
    run_.folds.push_back(std::move(fold));
  }
  if (run_.folds.empty()) return;
  std::vector<HeldOutScores> sets;
  for (const FoldRun& f : run_.folds) sets.push_back(f.scores);
  run_.cross_validated = PoolKinds(sets);
  Say(CrossValidatedReport(run_.folds.size(), run_.cross_validated));
}

}  // namespace

CalibrationProblem::CalibrationProblem(const Scene& scene, const ensemble::ReleaseSpec& release,
                                       const fieldobs::ObservationSet& observations,
                                       std::vector<ParameterSpec> parameters,
                                       const ObjectiveOptions& options, HeldOutChecks checks)
    : scene_(scene),
      release_(release),
      observations_(observations),
      parameters_(std::move(parameters)),
      options_(options),
      checks_(std::move(checks)),
      fit_([&] {
        SelectRuns(release, observations, checks_.holdout, false);  // refuses an unknown id
        return SelectRuns(release, observations, OtherRuns(release, checks_.holdout), true);
      }()),
      folds_(checks_.folds > 0 ? Folds(fit_.release, checks_.folds, checks_.seed)
                               : std::vector<std::vector<std::string>>{}),
      objective_(scene, fit_.release, fit_.observations, parameters_, options) {}

RunSubset CalibrationProblem::HeldOutRuns() const {
  return SelectRuns(release_, observations_, checks_.holdout, false);
}

RunSubset CalibrationProblem::FoldTraining(int f) const {
  return SelectRuns(fit_.release, fit_.observations,
                    OtherRuns(fit_.release, folds_[static_cast<std::size_t>(f)]), true);
}

RunSubset CalibrationProblem::FoldRuns(int f) const {
  return SelectRuns(fit_.release, fit_.observations, folds_[static_cast<std::size_t>(f)], false);
}

Objective CalibrationProblem::ObjectiveOn(const RunSubset& runs) const {
  return Objective(scene_, runs.release, runs.observations, parameters_, options_);
}

bool CalibrationSummary::BudgetEndedAFit() const {
  bool budget = BudgetEnded(fit);
  for (const FoldRun& f : folds) budget = budget || BudgetEnded(f.summary);
  return budget;
}

std::string CalibrationSummary::BriefReport() const {
  std::string out = fit.BriefReport();
  if (holdout) out += Format("; %zu runs held out", holdout->runs.size());
  if (!folds.empty()) out += Format("; %zu folds cross-validated", folds.size());
  return out;
}

std::string CalibrationSummary::FullReport() const {
  std::string out = fit.FullReport();
  if (roughness) out += roughness->Report() + ProfilesReport(profiles);
  if (uncertainty) out += uncertainty->Report();
  if (bootstrap) out += bootstrap->Report();
  if (seeds) out += seeds->Report();
  if (holdout) out += "Held-out runs:\n" + holdout->Report();
  for (std::size_t f = 0; f < folds.size(); ++f)
    out += Format("Fold %zu: ", f + 1) + folds[f].summary.BriefReport() + "\n";
  if (!folds.empty()) out += CrossValidatedReport(folds.size(), cross_validated);
  return out;
}

CalibrationSummary Calibrate(const CalibrationProblem& problem, const CalibrationOptions& options) {
  const auto t0 = std::chrono::steady_clock::now();
  CalibrationSummary run;
  run.threads = problem.objective().options().threads;
  Pipeline stages(problem, options, run);
  stages.Fit();
  stages.Roughness();
  stages.Uncertainty();
  stages.ScoreBeforeAndAfter();
  stages.HoldOut();
  stages.CrossValidate();
  run.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return run;
}

std::vector<std::string> CalibrationWarnings(const CalibrationSummary& run,
                                             const Objective& objective) {
  std::vector<std::string> out;
  const auto& coordinates = objective.parameters().coordinates();
  const Eigen::VectorXd& u = run.fit.best.u;
  for (std::size_t j = 0; j < coordinates.size(); ++j) {
    const Coordinate& c = coordinates[j];
    const bool flat = j < run.profiles.size() && !run.profiles[j].identified;
    const bool singular = run.uncertainty && j < run.uncertainty->identified.size() &&
                          !run.uncertainty->identified[j];
    if (flat)
      out.push_back(
          Format("%s is unidentified: over its whole range its profile changes the "
                 "objective's data term by %.3g, not more than %.3g (3 x the noise level, or "
                 "what noise alone spans over its points): the "
                 "observations do not constrain it, and its fitted value is %s%s",
                 c.name.c_str(), run.profiles[j].range, run.profiles[j].threshold,
                 c.prior                    ? "its prior's"
                 : objective.prior_center() ? "where the fit and the pull towards "
                                              "the reference table left it"
                                            : "where the fit left it",
                 RocksHint(run.profiles[j]).c_str()));
    else if (singular)
      out.push_back(c.name + " is unidentified by the covariance (J^T J is singular in it): the "
                             "observations do not constrain it");
    const auto jj = static_cast<Eigen::Index>(j);
    // A stated prior that the fit left far behind: the observations and the prior disagree.
    if (c.prior && jj < u.size()) {
      const double r = c.prior->Residual(c.ToValue(u[jj]));
      if (std::abs(r) > kPriorConflictSds)
        out.push_back(
            Format("%s = %g lies %.1f sds from its prior %s: the observations pull "
                   "away from what was stated; check the prior or the model",
                   c.name.c_str(), c.ToValue(u[jj]), std::abs(r), c.prior->Describe().c_str()));
    }
    if (jj < u.size() && (AtLowerBound(u[jj]) || AtUpperBound(u[jj]))) {
      const bool low = AtLowerBound(u[jj]);
      out.push_back(Format("%s lies at the %s bound of its range (%g): the optimum may lie "
                           "beyond it; widen the bounds where physics allows",
                           c.name.c_str(), low ? "lower" : "upper", low ? c.lower : c.upper));
    }
  }
  const double noise = run.roughness ? run.roughness->level() : 0;
  for (const ParameterProfile& p : run.profiles)
    for (std::size_t k = 0; k < p.f.size(); ++k)
      if (p.f[k] < run.fit.best.value - noise) {
        out.push_back(Format("the profile of %s found a lower objective (%.4g at %g) than the "
                             "reported optimum (%.4g), by more than the noise level %.3g: the fit "
                             "stopped short of the best point it could have found; refit from there "
                             "or with more starts",
                             p.name.c_str(), p.f[k], p.values[k], run.fit.best.value, noise));
        break;
      }
  const auto worse = [&out](const std::vector<HeldOutKind>& kinds, const char* which) {
    for (const HeldOutKind& k : kinds)
      if (std::isfinite(k.fitted) && std::isfinite(k.reference) && k.fitted > k.reference)
        out.push_back(Format("%s score %s worse with the fitted values than with the reference "
                             "table (%.4g against %.4g %s): the fit does not carry over to runs "
                             "it did not see",
                             which, k.kind.c_str(), k.fitted, k.reference, k.unit.c_str()));
  };
  if (run.holdout) worse(run.holdout->kinds, "the held-out runs");
  worse(run.cross_validated, "the cross-validated runs");
  return out;
}

}  // namespace talus::calibration
