#include "calibration/objective.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <sstream>

#include "common/error.hpp"
#include "common/statistics.hpp"
#include "ensemble/runner.hpp"
#include "fieldobs/samples.hpp"
#include "fieldobs/scores.hpp"
#include "fieldobs/validation.hpp"

namespace talus::calibration {
namespace {

// Mirrors fieldobs::Validate: scalars score against ensembles of at least 2 members.
constexpr int kMinMembers = 2;

}  // namespace

bool ObjectiveOptions::IsValid(std::string* why) const {
  std::ostringstream msg;
  for (const auto& [kind, weight] : weights)
    if (!std::isfinite(weight) || weight < 0)
      msg << "weights." << kind << " = " << weight << " must be >= 0";
  if (msg.str().empty() && (!std::isfinite(prior_weight) || prior_weight < 0))
    msg << "prior_weight = " << prior_weight << " must be >= 0";
  if (msg.str().empty() && threads < 0) msg << "threads = " << threads << " must be >= 0";
  if (msg.str().empty() && !(tolerance_m_s > 0 && tolerance_m_s < 1))
    msg << "tolerance_m_s = " << tolerance_m_s << " must be in (0, 1) m/s";
  if (msg.str().empty() && !(infeasible_value > 0 && std::isfinite(infeasible_value)))
    msg << "infeasible_value = " << infeasible_value << " must be > 0 and finite";
  if (msg.str().empty()) return true;
  if (why) *why = msg.str();
  return false;
}

Objective::Objective(const Scene& scene, const ensemble::ReleaseSpec& release,
                     const fieldobs::ObservationSet& observations,
                     std::vector<ParameterSpec> parameters, ObjectiveOptions options)
    : scene_(scene),
      release_(release),
      observations_(observations),
      parameters_(std::move(parameters), scene.ground, release.blocks),
      options_(std::move(options)) {
  std::string why;
  if (!options_.IsValid(&why)) throw InputError(why);
  scene_.options.tolerance_m_s = options_.tolerance_m_s;
  if (!scene_.IsValid(&why)) throw InputError("scene: " + why);
  if (!release_.IsValid(&why)) throw InputError("release: " + why);
  if (observations_.size() == 0) throw InputError("no observation to calibrate against");

  // Kinds in order of first appearance, as fieldobs::Validate orders them.
  const auto add_kind = [&](const std::string& kind) {
    for (const std::string& k : kinds_)
      if (k == kind) return;
    kinds_.push_back(kind);
  };
  for (const auto& o : observations_.scalars) {
    add_kind(fieldobs::ToString(o.quantity));
    episodes_ = episodes_ || o.quantity != fieldobs::Quantity::kRunout;
  }
  if (!observations_.deposits.empty()) add_kind("deposit");
  for (const auto& [kind, weight] : options_.weights) {
    bool known = false;
    for (const std::string& k : kinds_) known = known || k == kind;
    if (!known) {
      std::string list;
      for (const std::string& k : kinds_) list += (list.empty() ? "" : ", ") + k;
      throw InputError("weights." + kind + ": no observation of kind '" + kind +
                       "' (the observations are of: " + list + ")");
    }
  }
  for (const std::string& kind : kinds_) {
    const auto it = options_.weights.find(kind);
    weights_.push_back(it == options_.weights.end() ? 1.0 : it->second);
  }

  // Climatology scales: the leave-one-out climatology of fieldobs::Validate, which depends on the
  // observations (and, for deposits, on the runs' start positions) only.
  scales_.assign(kinds_.size(), 1.0);
  if (options_.normalise) {
    for (std::size_t k = 0; k < kinds_.size(); ++k) {
      std::vector<double> scores;
      if (kinds_[k] != "deposit") {
        std::vector<double> values;
        for (const auto& o : observations_.scalars)
          if (kinds_[k] == fieldobs::ToString(o.quantity)) values.push_back(o.value);
        if (static_cast<int>(values.size()) - 1 >= kMinMembers)
          scores = fieldobs::LeaveOneOutCrps(values);
      } else {
        // The other runs' observed displacements from their own release, from this run's start:
        // the energy score of this run's displacement against the others'.
        std::map<std::string, int> run_index;
        for (long r = 0; r < release_.release_count(); ++r)
          run_index.emplace(release_.ReleaseName(static_cast<int>(r)), static_cast<int>(r));
        std::vector<Eigen::Vector2d> displacements;
        for (const auto& o : observations_.deposits) {
          const auto r = o.run.empty() ? run_index.end() : run_index.find(o.run);
          if (r == run_index.end()) continue;
          const Eigen::Vector2d start =
              ensemble::Release(scene_, release_, release_.FirstRockOf(r->second))
                  .start.position_m.head<2>();
          displacements.push_back(o.xy_m - start);
        }
        if (static_cast<int>(displacements.size()) - 1 >= kMinMembers)
          scores = fieldobs::LeaveOneOutEnergyScores(displacements);
      }
      const double scale = Mean(scores);
      if (weights_[k] > 0 && !(scale > 0))
        throw InputError("objective: kind '" + kinds_[k] +
                         "' has no climatology score to normalise by (it needs at least 3 "
                         "observations of runs); set normalise = false or its weight to 0");
      scales_[k] = scale;
    }
  }

  // The prior: a coordinate's own, else the reference table's pull, if any.
  const std::vector<Coordinate>& coordinates = parameters_.coordinates();
  for (const Coordinate& c : coordinates)
    if (c.prior && options_.prior_weight == 0)
      throw InputError(c.name + ": a prior (" + c.prior->Describe() +
                       ") acts only with prior_weight > 0");
  if (options_.prior_weight > 0 && options_.prior_reference) {
    prior_center_ = parameters_.UnitOf(*options_.prior_reference);
    *prior_center_ = prior_center_->cwiseMax(0.0).cwiseMin(1.0);
  }
  if (options_.prior_weight > 0)
    for (int j = 0; j < dimension(); ++j)
      if (coordinates[static_cast<std::size_t>(j)].prior || prior_center_)
        prior_coordinates_.push_back(j);
  if (options_.prior_weight > 0 && prior_coordinates_.empty())
    throw InputError("prior_weight = " + std::to_string(options_.prior_weight) +
                     " but no prior: give a reference table or a parameter's own prior");

  // Residual groups: runs in order of first appearance; an observation of the whole scene alone.
  std::vector<std::string> runs;
  const auto group_of = [&](const std::string& run) {
    if (!run.empty())
      for (std::size_t g = 0; g < runs.size(); ++g)
        if (runs[g] == run) return static_cast<int>(g);
    runs.push_back(run);
    return static_cast<int>(runs.size() - 1);
  };
  for (const auto& o : observations_.scalars) residual_groups_.push_back(group_of(o.run));
  for (const auto& o : observations_.deposits) residual_groups_.push_back(group_of(o.run));
  for (std::size_t i = 0; i < observations_.scalars.size(); ++i)
    residual_groups_.push_back(residual_groups_[i]);
  residual_groups_.insert(residual_groups_.end(), prior_coordinates_.size(), -1);
}

Eigen::VectorXd Objective::PriorResiduals(const Eigen::VectorXd& u) const {
  Eigen::VectorXd r(static_cast<Eigen::Index>(prior_coordinates_.size()));
  for (std::size_t i = 0; i < prior_coordinates_.size(); ++i) {
    const int j = prior_coordinates_[i];
    const Coordinate& c = parameters_.coordinates()[static_cast<std::size_t>(j)];
    r[static_cast<Eigen::Index>(i)] =
        c.prior ? c.prior->Residual(c.ToValue(u[j])) : u[j] - (*prior_center_)[j];
  }
  return r;
}

GroundTable Objective::GroundOf(const Eigen::VectorXd& u) const {
  GroundTable table = scene_.ground;
  parameters_.Apply(u, table, nullptr);
  return table;
}

std::vector<ensemble::Block> Objective::BlocksOf(const Eigen::VectorXd& u) const {
  std::vector<ensemble::Block> blocks = release_.blocks;
  std::string why;
  if (!parameters_.ApplyShapes(u, blocks, &why)) throw InputError(why);
  return blocks;
}

ensemble::EnsembleReport RunWith(const EnsembleRunner& runner, const Scene& scene,
                                 const ensemble::ReleaseSpec& release,
                                 const ensemble::EnsembleOptions& options,
                                 fieldobs::EnsembleSamples* samples) {
  return runner ? runner(scene, release, options, samples)
                : ensemble::RunEnsemble(scene, release, options, samples);
}

Evaluation Objective::Evaluate(const Eigen::VectorXd& u) const { return Run(u, release_); }

Evaluation Objective::EvaluateWithSeed(const Eigen::VectorXd& u, std::uint64_t seed) const {
  ensemble::ReleaseSpec release = release_;
  release.seed = seed;
  return Run(u, release);
}

Evaluation Objective::Run(const Eigen::VectorXd& u, const ensemble::ReleaseSpec& release) const {
  const auto t0 = std::chrono::steady_clock::now();
  Evaluation e;
  e.u = u;
  e.values = parameters_.Values(u.cwiseMax(0.0).cwiseMin(1.0));
  e.kind_scores.assign(kinds_.size(), kNaN);
  e.kind_scored.assign(kinds_.size(), 0);
  const long m = static_cast<long>(observations_.size());
  const long m_scalars = static_cast<long>(observations_.scalars.size());
  e.residuals = Eigen::VectorXd::Zero(residual_count());
  const auto elapsed = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  };
  const auto infeasible = [&](const std::string& why, double violation) {
    e.feasible = false;
    e.infeasible = why;
    e.value = options_.infeasible_value * (1 + (std::isfinite(violation) ? violation : 1e3));
    e.data = kNaN;
    e.residuals.setConstant(std::sqrt(e.value / double(e.residuals.size())));
    e.wall_time_s = elapsed();
    return e;
  };

  // The scene's copy shares terrain and shapes; only its ground table changes.
  Scene scene = scene_;
  std::string why;
  double violation = 0;
  if (!parameters_.Apply(u, scene.ground, &why, &violation)) return infeasible(why, violation);
  // With shape parameters, a copy of the release whose blocks have the vector's knobs.
  ensemble::ReleaseSpec shaped;
  if (parameters_.has_shapes()) {
    shaped = release;
    if (!parameters_.ApplyShapes(u, shaped.blocks, &why)) return infeasible(why, 0);
  }
  const ensemble::ReleaseSpec& runs = parameters_.has_shapes() ? shaped : release;

  ensemble::EnsembleOptions options;
  options.threads = options_.threads;
  options.episodes = episodes_;
  options.progress = options_.progress;
  fieldobs::AddRecordersFor(observations_, scene_.terrain, runs, options);
  fieldobs::EnsembleSamples samples(runs);
  ensemble::EnsembleReport report;
  try {
    report = RunWith(options_.run_ensemble, scene, runs, options, &samples);
  } catch (const InputError& error) {
    // A rock whose own shape (shape_per_rock) the vector's knobs cannot make.
    if (!parameters_.has_shapes()) throw;
    return infeasible(error.what(), 0);
  }
  e.rocks = report.rocks;
  e.failed_rocks = report.count(EndReason::kFailed);
  fieldobs::ValidationOptions validation;
  validation.min_members = kMinMembers;
  const fieldobs::ValidationReport scores =
      fieldobs::Validate(observations_, samples, nullptr, validation);

  e.data = 0;
  for (std::size_t k = 0; k < kinds_.size(); ++k) {
    for (const fieldobs::KindSummary& s : scores.kinds)
      if (s.kind == kinds_[k]) {
        e.kind_scores[k] = s.mean_score;
        e.kind_scored[k] = s.scored;
      }
    if (weights_[k] == 0) continue;
    if (e.kind_scored[k] == 0)
      return infeasible("no observation of kind '" + kinds_[k] + "' could be scored", 0);
    e.data += weights_[k] * e.kind_scores[k] / scales_[k];
  }
  for (long i = 0; i < m; ++i) {
    const fieldobs::ObservationScore& s = scores.observations[static_cast<std::size_t>(i)];
    if (!s.scored) continue;
    for (std::size_t k = 0; k < kinds_.size(); ++k) {
      if (s.kind != kinds_[k] || weights_[k] == 0) continue;
      const double c = weights_[k] / (e.kind_scored[k] * scales_[k]);
      if (i >= m_scalars) {
        e.residuals[i] = std::sqrt(c * s.score);
        continue;
      }
      const fieldobs::ScalarObservation& o = observations_.scalars[static_cast<std::size_t>(i)];
      const double spread = std::min(
          s.score, fieldobs::CrpsEnsemble(samples.Values(o.quantity, o.run, o.zone), s.median));
      const double location = std::sqrt(c * (s.score - spread));
      e.residuals[i] = s.median < s.observed ? -location : location;
      e.residuals[m + i] = std::sqrt(c * spread);
    }
  }
  if (!prior_coordinates_.empty()) {
    const Eigen::VectorXd r = PriorResiduals(u);
    e.prior = options_.prior_weight * r.squaredNorm();
    e.residuals.tail(r.size()) = std::sqrt(options_.prior_weight) * r;
  }
  e.value = e.data + e.prior;
  e.wall_time_s = elapsed();
  return e;
}

}  // namespace talus::calibration
