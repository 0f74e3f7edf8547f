#pragma once
// The calibration objective: a parameter vector (unit coordinates, parameters.hpp) -> ground table
// -> the same rocks again (common random numbers: the same release, seed and per-rock streams for
// every evaluation) -> fieldobs scores -> one number.
//
//   f(u) = sum_kind weight_kind * mean_score_kind(u) / scale_kind  +  prior_weight * sum_j r_j^2
//
// mean_score_kind is the mean over the kind's scored observations of the CRPS (scalars) or energy
// score (deposits), in the kind's unit. scale_kind is the kind's climatology score (the mean of
// the leave-one-out climatology's scores, fieldobs/validation.hpp) when `normalise` is on, else 1:
// normalised, each term is 1 - skill vs climatology, dimensionless, so kinds of different units
// (m, m/s, rad/s) add up and a weight of 1 means "as important as explaining the spread between
// runs". Being fixed by the observations alone, the scale does not change the optimum of a single
// kind. The prior's residual r_j of coordinate j is its own prior's (parameters.hpp: Prior, the
// distance from the stated mean in sds), or, for a coordinate without one, u_j - u_ref_j, the pull
// in unit coordinates towards a reference table (Table 1 by default), or none.
//
// The objective owns a copy of the scene whose terrain and shapes are shared, immutable
// (solver/terrain.hpp), with the contact-solve tolerance of ObjectiveOptions in place of the
// scene's; each evaluation copies that scene (cheap), edits only its ground table and runs the
// ensemble. Evaluate is const and may be called from several threads at once; its
// result does not depend on the number of threads.

#include <Eigen/Core>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "calibration/parameters.hpp"
#include "ensemble/release.hpp"
#include "ensemble/runner.hpp"
#include "fieldobs/samples.hpp"
#include "fieldobs/observations.hpp"
#include "fieldobs/validation.hpp"
#include "solver/scene.hpp"

namespace talus::calibration {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// The contact solve's tolerance (m/s) of every evaluation unless the calibration asks for another.
// Finite differences through the ensemble see the solver's stopping rule: at 1e-4 m/s and looser
// the Ceres recovery test's stated standard error falls to 0.2-0.3 of the data's, at 1e-7 m/s it
// is 0.5 (bench/README.md, "Default tolerance"), so calibration keeps a tight solve whatever the
// simulations' default.
constexpr double kCalibrationTolerance_m_s = 1e-7;

// Runs every rock of `release` into `samples`, in rock order, and returns the counts of all of
// them. Empty (the default): ensemble::RunEnsemble in this process. A caller may divide the rocks
// among processes (MPI ranks): each runs a range and the samples are joined in rock order
// (fieldobs::EnsembleSamples::Append), so the objective is the same bits.
using EnsembleRunner = std::function<ensemble::EnsembleReport(
    const Scene& scene, const ensemble::ReleaseSpec& release,
    const ensemble::EnsembleOptions& options, fieldobs::EnsembleSamples* samples)>;

// Runs with `runner`, or in this process when it is empty.
ensemble::EnsembleReport RunWith(const EnsembleRunner& runner, const Scene& scene,
                                 const ensemble::ReleaseSpec& release,
                                 const ensemble::EnsembleOptions& options,
                                 fieldobs::EnsembleSamples* samples);

struct ObjectiveOptions {
  // Weight per observation kind ("runout", "deposit", "impact_speed_out", ... as in
  // fieldobs::ObservationScore::kind); kinds not listed weigh 1. A weight of 0 leaves a kind out.
  std::map<std::string, double> weights;
  bool normalise = true;  // divide each kind's mean score by its climatology score
  // Prior: prior_weight * sum_j r_j^2 over the coordinates with a prior: a coordinate's own
  // (ParameterSpec::prior), else u_j - u_ref_j with u_ref the unit coordinates of
  // `prior_reference` (clamped to [0, 1]) when it is given. Weight 0 (the default): no prior
  // (and a parameter's own prior is refused). Dimensionless when normalised.
  double prior_weight = 0;
  std::optional<GroundTable> prior_reference;
  int threads = 0;  // worker threads of each evaluation; 0: all cores
  // Contact-solve tolerance (m/s) of every evaluation: replaces the scene's
  // SolverOptions::tolerance_m_s. In (0, 1) as that is.
  double tolerance_m_s = kCalibrationTolerance_m_s;
  // Value of an infeasible vector (mu_min > mu_max, outside the box): no rock runs and the value
  // is infeasible_value * (1 + violation), finite so that every NLopt algorithm can use it.
  double infeasible_value = 1e3;
  // Called on the calling thread while rocks run (rocks done, total); may throw to stop.
  std::function<void(long, long)> progress;
  EnsembleRunner run_ensemble;  // how an evaluation's rocks run; empty: in this process

  bool IsValid(std::string* why) const;
};

// What one evaluation gave.
struct Evaluation {
  Eigen::VectorXd u;       // unit coordinates
  Eigen::VectorXd values;  // parameter values, one per coordinate
  bool feasible = true;
  std::string infeasible;  // why, when not feasible
  double value = kNaN;     // the objective
  double data = kNaN;      // the weighted score term
  double prior = 0;        // the prior term
  // Per kind (in the order of ObjectiveKinds()): mean score in the kind's unit, and scored count.
  std::vector<double> kind_scores;
  std::vector<int> kind_scored;
  // The residual vector of least squares (least_squares.hpp), whose sum of squares is the
  // objective. With c = weight / (n_kind * scale_kind) the factor of an observation's score:
  //  - one per observation (scalars, then deposits): for a scalar the *location* residual
  //      sign(median - observed) sqrt(c (CRPS - CRPS_at_median)),
  //    the CRPS's excess over the CRPS the same ensemble would score had the observation been
  //    its median (the smallest it can score, since the CRPS in the observation is smallest at
  //    the ensemble's median); signed, and about sqrt(c f(median)) (median - observed) near zero
  //    bias (f: the ensemble's density), so it crosses zero smoothly as the bias does.
  //    For a deposit (a 2-D energy score has no sign): sqrt(c energy_score);
  //  - then one per scalar observation, the *spread* residual sqrt(c CRPS_at_median): what the
  //    ensemble's width costs even without bias;
  //  - then one per coordinate with a prior: sqrt(prior_weight) r_j.
  // So the sum of squares is the data term plus the prior term. 0 for an observation that was
  // not scored. Objective::residual_groups() says which run each residual belongs to.
  Eigen::VectorXd residuals;
  long rocks = 0;
  long failed_rocks = 0;
  double wall_time_s = 0;
};

class Objective {
 public:
  // Copies what it needs. Throws talus::InputError when the parameters do not fit the scene's
  // ground table, an observation kind with a positive weight has no climatology scale while
  // normalising, or the options are invalid.
  Objective(const Scene& scene, const ensemble::ReleaseSpec& release,
            const fieldobs::ObservationSet& observations, std::vector<ParameterSpec> parameters,
            ObjectiveOptions options);

  Evaluation Evaluate(const Eigen::VectorXd& u) const;
  // The same with another release seed (other rocks): for the roughness measurement.
  Evaluation EvaluateWithSeed(const Eigen::VectorXd& u, std::uint64_t seed) const;

  // The scene's ground table as given, and its unit coordinates (the natural start).
  const GroundTable& base_ground() const { return scene_.ground; }
  Eigen::VectorXd StartPoint() const { return parameters_.UnitOf(scene_.ground); }
  // The ground table of a unit vector (the scene's table with the free fields set).
  GroundTable GroundOf(const Eigen::VectorXd& u) const;
  // The release's blocks with the shape parameters of a unit vector (clamped to [0, 1]); the
  // release's own without shape parameters. Throws talus::InputError when a shape cannot be made.
  std::vector<ensemble::Block> BlocksOf(const Eigen::VectorXd& u) const;

  const ParameterSet& parameters() const { return parameters_; }
  int dimension() const { return parameters_.size(); }
  const std::vector<std::string>& kinds() const { return kinds_; }
  const std::vector<double>& kind_scales() const { return scales_; }
  const std::vector<double>& kind_weights() const { return weights_; }
  const ObjectiveOptions& options() const { return options_; }
  const fieldobs::ObservationSet& observations() const { return observations_; }
  const ensemble::ReleaseSpec& release() const { return release_; }
  // The scene as every evaluation runs it: the given one with options().tolerance_m_s.
  const Scene& scene() const { return scene_; }
  std::optional<Eigen::VectorXd> prior_center() const { return prior_center_; }
  // The coordinates with a prior term, in order, and their residuals r_j at u.
  const std::vector<int>& prior_coordinates() const { return prior_coordinates_; }
  Eigen::VectorXd PriorResiduals(const Eigen::VectorXd& u) const;
  // The prior term at u: prior_weight * |PriorResiduals(u)|^2 (0 without a prior).
  double PriorTerm(const Eigen::VectorXd& u) const {
    return prior_coordinates_.empty() ? 0.0
                                      : options_.prior_weight * PriorResiduals(u).squaredNorm();
  }
  bool needs_episodes() const { return episodes_; }
  // Per residual (Evaluation::residuals): the group of observations it belongs to -- one group
  // per run, one per observation of the whole scene --, and -1 for the prior's. Observations of
  // one run share its rocks and are not independent; the groups are independent.
  const std::vector<int>& residual_groups() const { return residual_groups_; }
  int residual_count() const { return static_cast<int>(residual_groups_.size()); }

 private:
  Evaluation Run(const Eigen::VectorXd& u, const ensemble::ReleaseSpec& release) const;

  Scene scene_;
  ensemble::ReleaseSpec release_;
  fieldobs::ObservationSet observations_;
  ParameterSet parameters_;
  ObjectiveOptions options_;
  bool episodes_ = false;
  std::vector<std::string> kinds_;  // observation kinds in order of first appearance
  std::vector<double> weights_, scales_;
  std::optional<Eigen::VectorXd> prior_center_;
  std::vector<int> prior_coordinates_;
  std::vector<int> residual_groups_;
};

}  // namespace talus::calibration
