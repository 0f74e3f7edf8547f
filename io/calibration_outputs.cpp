#include "io/calibration_outputs.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>

#include "common/format.hpp"
#include "io/rocks_csv.hpp"
#include "io/validation_outputs.hpp"
#include "pointclouds/rock_source.hpp"

namespace talus::io {
namespace {

using calibration::Evaluation;
using calibration::Objective;
using nlohmann::json;

// The shortest text that reads back as exactly v: a fitted table written and read again is the
// table that was fitted (the ensemble resolves differences far below 10 significant digits).
std::string G(double v) { return std::isnan(v) ? "" : RoundTrip(v); }

// NaN and infinities as null.
json Number(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

json Vector(const Eigen::VectorXd& v) {
  json out = json::array();
  for (Eigen::Index k = 0; k < v.size(); ++k) out.push_back(Number(v[k]));
  return out;
}

// A category's name as a TOML key: bare when it may be ("medium_hard"), else a basic string
// ("zone 1", "meadow.v2": a bare dotted key would be a nested table), with quotes, backslashes and
// control characters escaped.
std::string TomlKey(const std::string& name) {
  const bool bare = !name.empty() && std::all_of(name.begin(), name.end(), [](char c) {
    return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_' ||
           c == '-';
  });
  if (bare) return name;
  std::string out = "\"";
  for (const char c : name) {
    const auto u = static_cast<unsigned char>(c);
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (u < 0x20 || u == 0x7f) {
      char escaped[8];
      std::snprintf(escaped, sizeof escaped, "\\u%04x", u);
      out += escaped;
    } else {
      out += c;  // UTF-8 as it came from the scene's TOML
    }
  }
  return out + "\"";
}

// Touched categories, in table order.
std::vector<int> Touched(const Objective& objective, const GroundTable& table) {
  std::set<int> indices;
  for (const auto& spec : objective.parameters().specs())
    if (!spec.IsShape()) indices.insert(table.IndexOfName(spec.category));
  return {indices.begin(), indices.end()};
}

json Kinds(const Objective& objective, const Evaluation& before, const Evaluation& after) {
  json out = json::array();
  for (std::size_t k = 0; k < objective.kinds().size(); ++k) {
    const std::string& kind = objective.kinds()[k];
    std::string unit = "m";
    for (const auto& o : objective.observations().scalars)
      if (kind == fieldobs::ToString(o.quantity)) unit = fieldobs::UnitOf(o.quantity);
    out.push_back({{"kind", kind},
                   {"unit", unit},
                   {"weight", objective.kind_weights()[k]},
                   {"scale", Number(objective.kind_scales()[k])},
                   {"score_before",
                    before.kind_scores.size() > k ? Number(before.kind_scores[k]) : json(nullptr)},
                   {"score_after",
                    after.kind_scores.size() > k ? Number(after.kind_scores[k]) : json(nullptr)},
                   {"scored_before", before.kind_scored.size() > k ? before.kind_scored[k] : 0},
                   {"scored_after", after.kind_scored.size() > k ? after.kind_scored[k] : 0}});
  }
  return out;
}

json Matrix(const Eigen::MatrixXd& m) {
  json out = json::array();
  for (Eigen::Index r = 0; r < m.rows(); ++r) out.push_back(Vector(m.row(r).transpose()));
  return out;
}

// The bootstrap over runs: its standard errors, percentile intervals, correlations and refits.
json BootstrapJson(const calibration::Bootstrap& b) {
  json identified = json::array();
  for (bool i : b.identified) identified.push_back(i);
  return {{"method",
           "bootstrap over runs: resamples of the runs with replacement, each refitted by "
           "BOBYQA from a start within start_spread_unit of the optimum"},
          {"resamples", b.resamples},
          {"runs", b.groups},
          {"seed", b.seed},
          {"resolution_unit", b.resolution},
          {"start_spread_unit", b.start_spread},
          {"level", b.level},
          {"names", b.names},
          {"identified", identified},
          {"standard_error", Vector(b.standard_error)},
          {"standard_error_unit", Vector(b.standard_error_unit)},
          {"lower", Vector(b.lower)},
          {"upper", Vector(b.upper)},
          {"correlation", Matrix(b.correlation)},
          {"refits", Matrix(b.refits)},
          {"refits_at_budget", b.refits_at_budget},
          {"evaluations", b.evaluations},
          {"from_cache", b.cached},
          {"note", b.note},
          {"wall_time_s", b.wall_time_s}};
}

// The seed refits: their spread and the standard errors and intervals combined with the bootstrap.
json SeedRefitsJson(const calibration::SeedRefits& s) {
  json seeds = json::array();
  for (std::uint64_t seed : s.release_seeds) seeds.push_back(seed);
  return {{"method",
           "refits with other release seeds, each by BOBYQA from the optimum; combined standard "
           "error sqrt(bootstrap^2 + (seed sd (1 + 1/sqrt(2 (S - 1))))^2); interval: each side "
           "of the bootstrap's widened in quadrature by z times the seeds' part"},
          {"seeds", s.seeds},
          {"release_seeds", seeds},
          {"level", s.level},
          {"names", s.names},
          {"refits", Matrix(s.refits)},
          {"seed_sd", Vector(s.sd)},
          {"seed_sd_unit", Vector(s.sd_unit)},
          {"seed_standard_error", Vector(s.seed_standard_error)},
          {"combined_standard_error", Vector(s.combined_standard_error)},
          {"combined_standard_error_unit", Vector(s.combined_standard_error_unit)},
          {"lower", Vector(s.lower)},
          {"upper", Vector(s.upper)},
          {"refits_at_budget", s.refits_at_budget},
          {"evaluations", s.evaluations},
          {"note", s.note},
          {"wall_time_s", s.wall_time_s}};
}

json HeldOutKinds(const std::vector<calibration::HeldOutKind>& kinds) {
  json out = json::array();
  for (const auto& k : kinds)
    out.push_back({{"kind", k.kind},
                   {"unit", k.unit},
                   {"observations", k.observations},
                   {"scored", k.scored},
                   {"crps_fitted", Number(k.fitted)},
                   {"crps_reference", Number(k.reference)}});
  return out;
}

// Per block and kind, the simulated mean's bias against the observed (fieldobs::BiasByBlock), over
// the runs of `observations` (the runs' blocks from `release`, the event's whole release).
json BlocksJson(const std::vector<fieldobs::ObservationScore>& observations,
                const ensemble::ReleaseSpec& release) {
  return json(BlockBiasJson(fieldobs::BiasByBlock(observations, release)));
}

json HeldOut(const calibration::HeldOutScores& s, const ensemble::ReleaseSpec& release) {
  return {{"runs", s.runs},
          {"kinds", HeldOutKinds(s.kinds)},
          {"blocks", BlocksJson(s.observations, release)},
          {"rocks", s.rocks},
          {"wall_time_s", s.wall_time_s}};
}

// Per coordinate: its parameters, bounds, initial and fitted values, and its profile when measured.
json ParametersJson(const Objective& objective, const calibration::CalibrationSummary& run) {
  const calibration::OptimizerSummary& s = run.fit;
  json parameters = json::array();
  const auto& coordinates = objective.parameters().coordinates();
  for (std::size_t j = 0; j < coordinates.size(); ++j) {
    const auto& c = coordinates[j];
    const auto k = static_cast<Eigen::Index>(j);
    json members = json::array();
    for (int m : c.members) members.push_back(objective.parameters().specs()[m].Name());
    const auto& first = objective.parameters().specs()[c.members.front()];
    json p = {{"name", c.name},
              {"parameters", members},
              // Which part of the fit: the ground table, or a block's shape.
              {"part", first.IsShape() ? "shape" : "ground"},
              {"field", first.FieldName()},
              {"unit", first.Unit()},
              {"lower", c.lower},
              {"upper", c.upper},
              {"log", c.log},
              {"initial", Number(s.initial.values[k])},
              {"final", Number(s.best.values[k])},
              {"final_unit_coordinate", Number(s.best.u[k])}};
    // The prior on this coordinate: its own (and where the fit ended, in sds from its mean), the
    // pull towards the reference table, or none.
    const std::vector<int>& with_prior = objective.prior_coordinates();
    const auto at = std::find(with_prior.begin(), with_prior.end(), static_cast<int>(j));
    if (at == with_prior.end()) {
      p["prior"] = nullptr;
    } else {
      const double r = objective.PriorResiduals(s.best.u)[at - with_prior.begin()];
      if (c.prior && c.prior->IsLogNormal())
        p["prior"] = {{"kind", "log-normal"}, {"mean", c.prior->mean}, {"factor", c.prior->factor}};
      else if (c.prior)
        p["prior"] = {{"kind", "normal"}, {"mean", c.prior->mean}, {"sd", c.prior->sd}};
      else
        p["prior"] = {{"kind", "reference"},
                      {"unit_coordinate", Number((*objective.prior_center())[k])}};
      p["prior"]["final_residual"] = Number(r);
    }
    if (j < run.profiles.size()) {
      const auto& profile = run.profiles[j];
      p["identified"] = profile.identified;
      p["profile"] = {{"u", profile.u},
                      {"values", profile.values},
                      {"objective", profile.f},
                      {"range", Number(profile.range)},
                      {"threshold", Number(profile.threshold)},
                      {"rocks_to_identify", Number(profile.rocks_to_identify)},
                      {"within_noise", profile.within_noise}};
    } else {
      p["identified"] = nullptr;
    }
    parameters.push_back(p);
  }
  return parameters;
}

// Per parameter, the standard errors and intervals of the covariance, the seed refits and the
// bootstrap, when there is an uncertainty.
void AddStandardErrors(const calibration::CalibrationSummary& run, json& parameters) {
  if (!run.uncertainty) return;
  const auto& u = *run.uncertainty;
  for (std::size_t k = 0; k < u.names.size() && k < parameters.size(); ++k)
    parameters[k]["standard_error"] = Number(u.standard_error[static_cast<Eigen::Index>(k)]);
  if (run.seeds)
    for (std::size_t k = 0; k < run.seeds->names.size() && k < parameters.size(); ++k) {
      const auto q = static_cast<Eigen::Index>(k);
      parameters[k]["seed_sd"] = Number(run.seeds->sd[q]);
      parameters[k]["combined_standard_error"] = Number(run.seeds->combined_standard_error[q]);
      parameters[k]["combined_interval"] = {Number(run.seeds->lower[q]),
                                            Number(run.seeds->upper[q])};
    }
  if (run.bootstrap)
    for (std::size_t k = 0; k < run.bootstrap->names.size() && k < parameters.size(); ++k) {
      const auto q = static_cast<Eigen::Index>(k);
      parameters[k]["bootstrap_standard_error"] = Number(run.bootstrap->standard_error[q]);
      parameters[k]["bootstrap_interval"] = {Number(run.bootstrap->lower[q]),
                                             Number(run.bootstrap->upper[q])};
    }
}

json StartsJson(const calibration::OptimizerSummary& s) {
  json starts = json::array();
  for (const auto& r : s.starts)
    starts.push_back({{"start", Vector(r.u0)},
                      {"best", Vector(r.best_u)},
                      {"best_objective", Number(r.best_value)},
                      {"evaluations", r.evaluations},
                      {"result", r.result}});
  return starts;
}

// The covariance in physical units, null in the rows and columns of unidentified parameters (they
// have none: the value 0 there would read as certainty).
json CovarianceJson(const calibration::Uncertainty& u) {
  json rows = json::array();
  for (Eigen::Index i = 0; i < u.covariance.rows(); ++i) {
    json row = json::array();
    for (Eigen::Index k = 0; k < u.covariance.cols(); ++k) {
      const bool known = static_cast<std::size_t>(std::max(i, k)) < u.identified.size() &&
                         u.identified[static_cast<std::size_t>(i)] &&
                         u.identified[static_cast<std::size_t>(k)];
      row.push_back(known ? Number(u.covariance(i, k)) : json(nullptr));
    }
    rows.push_back(row);
  }
  return rows;
}

// The sandwich covariance at one point.
json SandwichJson(const calibration::Uncertainty& u) {
  json identified = json::array(), weak = json::array();
  for (std::size_t k = 0; k < u.identified.size(); ++k) {
    identified.push_back(bool(u.identified[k]));
    weak.push_back(bool(u.weak[k]));
  }
  return {{"method",
           "sandwich covariance H^-1 V H^-1 over runs, (J^T J)^-1 from "
           "ceres::Covariance (dense SVD)"},
          {"computed", u.computed},
          {"rank_deficient", u.rank_deficient},
          {"names", u.names},
          {"values", Vector(u.values)},
          {"standard_error", Vector(u.standard_error)},
          {"standard_error_unit", Vector(u.standard_error_unit)},
          {"correlation", Matrix(u.correlation)},
          {"covariance", CovarianceJson(u)},
          {"identified", identified},
          {"weak", weak},
          {"runs", u.groups},
          {"finite_difference_step", Number(u.fd_step)},
          {"stationary_located", u.stationary_located},
          {"offset_limited", u.offset_limited},
          {"offset_unit", Vector(u.offset_unit)},
          {"stationary_values", Vector(u.stationary_values)},
          {"note", u.note},
          {"evaluations", u.evaluations},
          {"wall_time_s", u.wall_time_s}};
}

// The sandwich covariance, with the bootstrap and the seed refits beside it; null without one.
json UncertaintyJson(const calibration::CalibrationSummary& run) {
  if (!run.uncertainty) return nullptr;
  json j = SandwichJson(*run.uncertainty);
  j["bootstrap"] = run.bootstrap ? BootstrapJson(*run.bootstrap) : json(nullptr);
  j["seeds"] = run.seeds ? SeedRefitsJson(*run.seeds) : json(nullptr);
  return j;
}

// Each fold's fit and scores, and the scores pooled over the folds; null without folds.
json CrossValidationJson(const calibration::CalibrationSummary& run,
                         const ensemble::ReleaseSpec& release) {
  if (run.folds.empty()) return nullptr;
  json folds = json::array();
  std::vector<fieldobs::ObservationScore> pooled;
  for (const calibration::FoldRun& f : run.folds) {
    pooled.insert(pooled.end(), f.scores.observations.begin(), f.scores.observations.end());
    json fold = HeldOut(f.scores, release);
    fold["fitted"] = Vector(f.summary.best.values);
    fold["objective"] = Number(f.summary.best.value);
    fold["evaluations"] = f.summary.evaluations();
    fold["termination"] = calibration::ToString(f.summary.termination);
    folds.push_back(fold);
  }
  return {{"folds", folds},
          {"kinds", HeldOutKinds(run.cross_validated)},
          {"blocks", BlocksJson(pooled, release)}};
}

json RoughnessJson(const std::optional<calibration::RoughnessReport>& roughness) {
  if (!roughness) return nullptr;
  const auto& r = *roughness;
  return {{"at_objective", Number(r.value)},
          {"steps", r.steps},
          {"change", r.change},
          {"noise", Number(r.noise)},
          {"seed_values", r.seed_values},
          {"seed_sd", Number(r.seed_sd)},
          {"level", Number(r.level())},
          {"level_is_sampling_noise", r.LevelIsSamplingNoise()},
          {"finite_difference_step", Number(r.fd_step)},
          {"ftol_abs", Number(r.ftol_abs)},
          {"evaluations", r.evaluations}};
}

}  // namespace

// The fields written for a fitted category: every row of kGroundFields that applies to it, with
// its model when that is not the default.
std::string FittedValueNote(const Objective& objective, const calibration::CalibrationSummary& run,
                            const std::string& name);

// Why a fitted value deserves a second look, as a TOML comment (" # ..."), or "": the coordinate
// of `category`'s `field` is unidentified (its profile is flat, or the covariance found it so), or
// the fit lies at a bound of its range (calibration::AtLowerBound, AtUpperBound: the optimum may
// lie beyond).
std::string FittedValueNote(const Objective& objective, const calibration::CalibrationSummary& run,
                            const std::string& category, calibration::GroundField field) {
  calibration::ParameterSpec spec;
  spec.category = category;
  spec.field = field;
  return FittedValueNote(objective, run, spec.Name());
}

// The same for the parameter named `name` (ParameterSpec::Name()).
std::string FittedValueNote(const Objective& objective, const calibration::CalibrationSummary& run,
                            const std::string& name) {
  const auto& coordinates = objective.parameters().coordinates();
  const auto& specs = objective.parameters().specs();
  for (std::size_t j = 0; j < coordinates.size(); ++j) {
    const calibration::Coordinate& c = coordinates[j];
    const bool here = std::any_of(c.members.begin(), c.members.end(), [&](int m) {
      return specs[static_cast<std::size_t>(m)].Name() == name;
    });
    if (!here) continue;
    std::string note;
    const bool unidentified = (j < run.profiles.size() && !run.profiles[j].identified) ||
                              (run.uncertainty && j < run.uncertainty->identified.size() &&
                               !run.uncertainty->identified[j]);
    if (unidentified)
      note +=
          "unidentified: the observations do not constrain it (flat profile); the value is "
          "where the fit left it";
    const auto jj = static_cast<Eigen::Index>(j);
    if (run.fit.best.u.size() > jj) {
      const double u = run.fit.best.u[jj];
      if (calibration::AtLowerBound(u) || calibration::AtUpperBound(u)) {
        const bool low = calibration::AtLowerBound(u);
        if (!note.empty()) note += "; ";
        note += std::string("at the ") + (low ? "lower" : "upper") + " bound of its range (" +
                G(low ? c.lower : c.upper) + "): the optimum may lie beyond it";
      }
    }
    return note.empty() ? "" : "  # " + note;
  }
  return "";
}

std::string GroundTableToml(const CalibrationFile& file, const Objective& objective,
                            const GroundTable& fitted, const calibration::CalibrationSummary* run) {
  std::string out = "# Ground table fitted by talus calibrate " + file.path +
                    " (docs/calibration.md).\n# Paste into a scene file, or append to one. A value "
                    "with a comment is not supported by the observations.\n";
  if (objective.parameters().has_shapes())
    out += "# Fitted jointly with block shapes: use it with the blocks of shape_table.toml.\n";
  for (int k : Touched(objective, fitted)) {
    const GroundCategory& c = fitted.category(k);
    out += "\n[ground." + TomlKey(c.name) + "]\ncode = " + std::to_string(c.code) + "\n";
    if (c.params.IsSoil()) out.append("model = \"").append(ToString(c.params.model)).append("\"\n");
    for (std::size_t i = 0; i < kGroundFields.size(); ++i) {
      const GroundFieldInfo& f = kGroundFields[i];
      if (f.group == GroundFieldInfo::Group::kDragLayer || !GroundFieldApplies(f, c.params))
        continue;
      out.append(f.key).append(" = ").append(G(c.params.*f.member));
      if (run)
        out += FittedValueNote(objective, *run, c.name, static_cast<calibration::GroundField>(i));
      out += "\n";
    }
  }
  return out;
}

std::string ShapeTableToml(const CalibrationFile& file, const Objective& objective,
                           const calibration::CalibrationSummary& run) {
  std::string out =
      "# Block shapes fitted by talus calibrate " + file.path +
      " (docs/calibration.md), jointly with\n# the ground table in ground_table.toml: use the "
      "two together. Each [blocks.<id>] table is the\n# whole block with its fitted knobs: it "
      "replaces the block in the scene's [blocks] (a block of\n# the blocks file: drop its row). "
      "A value with a comment is not supported by the observations.\n";
  const auto& specs = objective.parameters().specs();
  const std::vector<pointclouds::RockSpec>& block_specs = file.event.scene.block_specs;
  for (std::size_t b = 0; b < run.fitted_blocks.size() && b < block_specs.size(); ++b) {
    const ensemble::Block& block = run.fitted_blocks[b];
    const pointclouds::RockSpec& spec = block_specs[b];
    std::string notes;  // of the fitted knobs
    bool fitted = false;
    for (const calibration::ParameterSpec& p : specs) {
      if (!p.IsShape() || p.block != block.id) continue;
      fitted = true;
      const std::string note = FittedValueNote(objective, run, p.Name());
      if (!note.empty()) notes += "# " + p.FieldName() + ":" + note.substr(3) + "\n";
    }
    if (!fitted) continue;
    out += "\n[blocks." + TomlKey(block.id) + "]\n" + notes;
    out += "shape = \"" + spec.builtin + "\"\n";
    out += "size_m = [" + G(block.knobs.size_m.x()) + ", " + G(block.knobs.size_m.y()) + ", " +
           G(block.knobs.size_m.z()) + "]\n";
    if (spec.mass_kg)
      out += "mass_kg = " + G(*spec.mass_kg) + "\n";
    else
      out += "# no mass: the density of [blocks] (" + G(spec.density_kg_m3) + " kg/m3) sets it\n";
    if (spec.builtin == "rock") {
      out += "roughness = " + G(block.knobs.roughness) + "\n";
      out += "points = " + std::to_string(spec.points) + "\n";
      out += "shape_seed = " + std::to_string(block.knobs.shape_seed) + "\n";
    }
  }
  return out;
}

// One row per fitted category; the soil's columns when some fitted category has the soil.
std::string GroundTableCsv(const Objective& objective, const GroundTable& fitted) {
  const std::vector<int> touched = Touched(objective, fitted);
  bool soil = false;
  for (int k : touched) soil = soil || fitted.params(k).IsSoil();
  std::vector<const GroundFieldInfo*> columns;
  for (const GroundFieldInfo& f : kGroundFields)
    if (f.group == GroundFieldInfo::Group::kFriction ||
        (soil && f.group == GroundFieldInfo::Group::kSoil))
      columns.push_back(&f);
  std::string out = soil ? "category,code,model" : "category,code";
  for (const GroundFieldInfo* f : columns) out.append(",").append(f->key);
  out += "\n";
  for (int k : touched) {
    const GroundCategory& c = fitted.category(k);
    out += CsvField(c.name) + "," + std::to_string(c.code);
    if (soil) out.append(",").append(ToString(c.params.model));
    for (const GroundFieldInfo* f : columns) out.append(",").append(G(c.params.*f->member));
    out += "\n";
  }
  return out;
}

std::string CalibrationJson(const CalibrationFile& file, const Objective& objective,
                            const calibration::CalibrationSummary& run,
                            const std::string& version) {
  const calibration::OptimizerSummary& s = run.fit;
  json parameters = ParametersJson(objective, run);
  AddStandardErrors(run, parameters);
  const ensemble::ReleaseSpec& release = objective.release();
  json j = {{"version", version},
            {"calibration_file", file.path},
            {"event", file.event.path},
            {"inputs", file.inputs},
            {"inputs_sha256", file.inputs_hash},
            {"runs", release.release_count()},
            {"rocks_per_run", release.rocks_per_release},
            {"seed", release.seed},
            {"solver",
             {{"tolerance_m_s", objective.options().tolerance_m_s},
              {"tolerance_source", file.tolerance_source}}},
            {"threads", run.threads},
            {"algorithm", s.algorithm},
            {"termination", calibration::ToString(s.termination)},
            {"message", s.message},
            {"parameters", parameters},
            {"objective",
             {{"before", Number(s.initial.value)},
              {"after", Number(s.best.value)},
              {"data_after", Number(s.best.data)},
              {"prior_after", Number(s.best.prior)},
              {"normalised", objective.options().normalise},
              {"prior_weight", objective.options().prior_weight},
              {"prior_reference",
               objective.options().prior_weight > 0 ? json(file.prior_reference) : json(nullptr)}}},
            {"kinds", Kinds(objective, s.initial, s.best)},
            {"evaluations", s.evaluations()},
            {"cache_hits", s.cache_hits},
            {"replayed_from_checkpoint", s.replayed},
            {"finite_difference_step", Number(s.fd_step)},
            {"finite_difference_shrink", Number(s.fd_shrink)},
            {"starts", StartsJson(s)},
            {"timings",
             {{"calibration_s", s.wall_time_s},
              // Over the evaluations this run made (not those replayed from a checkpoint).
              {"evaluations_per_s", s.wall_time_s > 0 && s.evaluations() > s.replayed
                                        ? json((s.evaluations() - s.replayed) / s.wall_time_s)
                                        : json(nullptr)},
              {"roughness_and_profiles_s",
               run.roughness ? json(run.roughness->wall_time_s) : json(nullptr)},
              {"total_s", run.wall_time_s}}}};
  j["uncertainty"] = UncertaintyJson(run);
  j["not_scored"] = file.event.not_scored;  // observed values without a simulated counterpart
  // The scene's and the result's (calibration::CalibrationWarnings), as printed.
  std::vector<std::string> warnings = file.event.scene.warnings;
  for (const std::string& w : calibration::CalibrationWarnings(run, objective))
    warnings.push_back(w);
  j["warnings"] = warnings;
  const ensemble::ReleaseSpec& all_runs = file.event.scene.release;
  // The fitted runs scored with the fitted values, per block: what the fit leaves in each block.
  j["fitted_runs_blocks"] = BlocksJson(run.after.observations, all_runs);
  j["holdout"] = run.holdout ? HeldOut(*run.holdout, all_runs) : json(nullptr);
  j["cross_validation"] = CrossValidationJson(run, all_runs);
  j["roughness"] = RoughnessJson(run.roughness);
  return j.dump(2) + "\n";
}

std::string UncertaintyJson(const calibration::Uncertainty& uncertainty) {
  return SandwichJson(uncertainty).dump(2) + "\n";
}

std::string HistoryCsv(const Objective& objective, const calibration::OptimizerSummary& summary) {
  std::string out = "evaluation,start,feasible,objective,data,prior";
  // Cells appended one by one (GCC 12 warns wrongly about chains of std::string operator+).
  const auto cell = [&out](const std::string& text) {
    out += ',';
    out += text;
  };
  for (const auto& c : objective.parameters().coordinates()) cell(CsvField(c.name));
  for (const std::string& kind : objective.kinds()) cell("score_" + kind);
  out += ",wall_time_s,note\n";
  for (std::size_t i = 0; i < summary.history.size(); ++i) {
    const Evaluation& e = summary.history[i];
    out += std::to_string(i);
    cell(std::to_string(summary.history_start[i]));
    cell(e.feasible ? "1" : "0");
    cell(G(e.value));
    cell(G(e.data));
    cell(G(e.prior));
    for (Eigen::Index k = 0; k < e.values.size(); ++k) cell(G(e.values[k]));
    for (double v : e.kind_scores) cell(G(v));
    std::string note = e.infeasible;
    for (char& c : note)
      if (c == ',' || c == '"' || c == '\n') c = ';';
    cell(G(e.wall_time_s));
    cell(note);
    out += '\n';
  }
  return out;
}

}  // namespace talus::io
