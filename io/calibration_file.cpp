#include "io/calibration_file.hpp"

#include <toml++/toml.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "calibration/designs.hpp"
#include "calibration/holdout.hpp"
#include "common/closest_name.hpp"
#include "common/error.hpp"
#include "common/sha256.hpp"
#include "io/toml_section.hpp"

namespace talus::io {
namespace {

using calibration::ParameterSpec;

// The fields a calibration may free (kGroundFields' calibrated rows).
std::vector<std::string> CalibratedFields() {
  std::vector<std::string> fields;
  for (const GroundFieldInfo& f : kGroundFields)
    if (f.calibrated) fields.emplace_back(f.key);
  return fields;
}
const std::vector<std::string> kFields = CalibratedFields();
const std::vector<std::string> kShapeFields = {"roughness", "size_x_m", "size_y_m", "size_z_m"};

std::string Hint(const std::string& word, const std::vector<std::string>& known) {
  const std::string hint = ClosestName(word, known);
  return hint.empty() ? "" : " (did you mean '" + hint + "'?)";
}

std::vector<std::string> ObservedKinds(const fieldobs::ObservationSet& observations) {
  std::vector<std::string> kinds;
  const auto add = [&](const std::string& kind) {
    if (std::find(kinds.begin(), kinds.end(), kind) == kinds.end()) kinds.push_back(kind);
  };
  for (const auto& o : observations.scalars) add(fieldobs::ToString(o.quantity));
  if (!observations.deposits.empty()) add("deposit");
  return kinds;
}

std::string Join(const std::vector<std::string>& items) {
  std::string out;
  for (const std::string& s : items) out += (out.empty() ? "" : ", ") + s;
  return out;
}

void LoadParameters(const Context& context, const toml::table& root, CalibrationFile& out) {
  const toml::node* node = root.get("parameters");
  if (!node)
    context.Fail(&root, "parameters",
                 "missing: give [[parameters]] tables (category, field, lower, upper)");
  const toml::array* array = node->as_array();
  if (!array || array->empty())
    context.Fail(node, "parameters",
                 "expected [[parameters]] tables (category, field, lower, upper)");
  const GroundTable& table = out.event.scene.scene.ground;
  std::vector<std::string> categories;
  for (int k = 0; k < table.size(); ++k) categories.push_back(table.category(k).name);
  std::vector<const toml::node*> where;
  for (std::size_t k = 0; k < array->size(); ++k) {
    const std::string name = "parameters[" + std::to_string(k) + "]";
    const toml::table* t = array->get(k)->as_table();
    if (!t) context.Fail(array->get(k), name, "expected a table (category, field, lower, upper)");
    const Section s(context, t, name,
                    {"category", "block", "field", "lower", "upper", "log", "tie", "prior"});
    ParameterSpec spec;
    if (s.Has("category") == s.Has("block"))
      s.Fail(s.Has("block") ? "block" : "category",
             s.Has("block") ? "give a ground category or a block, not both"
                            : "missing: a ground category of the scene (or a block, for a "
                              "shape parameter)");
    if (s.Has("block")) {
      spec.block = s.String("block", "");
      std::vector<std::string> blocks;
      for (const ensemble::Block& b : out.event.scene.release.blocks) blocks.push_back(b.id);
      if (std::find(blocks.begin(), blocks.end(), spec.block) == blocks.end())
        s.Fail("block", "unknown block '" + spec.block + "'" + Hint(spec.block, blocks) +
                            (blocks.empty() ? "; the scene has no [blocks]"
                                            : "; the scene has " + Join(blocks)));
      if (!s.Has("field")) s.Fail("field", "missing: one of " + Join(kShapeFields));
      const std::string field = s.String("field", "");
      if (!calibration::ParseShapeField(field, &spec.shape_field))
        s.Fail("field", "unknown shape parameter '" + field + "'" + Hint(field, kShapeFields) +
                            "; known: " + Join(kShapeFields));
    } else {
      spec.category = s.String("category", "");
      if (table.IndexOfName(spec.category) < 0)
        s.Fail("category", "unknown ground category '" + spec.category + "'" +
                               Hint(spec.category, categories) + "; the scene has " +
                               Join(categories));
      if (!s.Has("field")) s.Fail("field", "missing: one of " + Join(kFields));
      const std::string field = s.String("field", "");
      if (!calibration::ParseGroundField(field, &spec.field))
        s.Fail("field", "unknown parameter '" + field + "'" + Hint(field, kFields) +
                            "; known: " + Join(kFields));
    }
    for (const char* bound : {"lower", "upper"})
      if (!s.Has(bound))
        s.Fail(bound, std::string("missing: the ") + bound + " bound, in " + spec.Unit());
    spec.lower = s.Number("lower", 0);
    spec.upper = s.Number("upper", 0);
    if (s.Has("log")) spec.log = s.Bool("log", false);
    spec.tie = s.String("tie", "");
    if (const toml::node* prior = s.Node("prior")) {
      if (!prior->is_table())
        s.Fail("prior",
               "expected a table { mean = ..., sd = ... } or { mean = ..., factor = ... }");
      const Section p(context, prior->as_table(), name + ".prior", {"mean", "sd", "factor"});
      if (!p.Has("mean"))
        p.Fail("mean", std::string("missing: the prior's mean, in ") + spec.Unit());
      spec.prior =
          calibration::Prior{p.Number("mean", 0), p.Number("sd", 0), p.Number("factor", 0)};
    }
    std::string why;
    if (!spec.IsValid(&why))
      s.Fail(why.find(": prior:") != std::string::npos ? "prior"
             : spec.upper > spec.lower                 ? "lower"
                                                       : "upper",
             why);
    out.parameters.push_back(spec);
    where.push_back(t);
  }
  // Ties, duplicates and mu_min <= mu_max, against the scene's table.
  try {
    const calibration::ParameterSet set(out.parameters, table, out.event.scene.release.blocks);
  } catch (const InputError& e) {
    // Name the parameter the message starts with.
    const std::string message = e.what();
    const toml::node* at = node;
    for (std::size_t k = 0; k < out.parameters.size(); ++k)
      if (message.rfind(out.parameters[k].Name() + ":", 0) == 0) at = where[k];
    context.Fail(at, "parameters", message);
  }
}

constexpr const char* kPriorNeedsWeight =
    "a parameter's prior acts only with [objective] prior_weight > 0 (1: a departure of one sd "
    "costs as much as a kind's climatology score)";

void LoadObjective(const Context& context, const toml::table* table, CalibrationFile& out) {
  const Section s(context, table, "objective",
                  {"weights", "normalise", "prior_weight", "prior_reference"});
  const std::vector<std::string> kinds = ObservedKinds(out.event.observations);
  if (const toml::node* node = s.Node("weights")) {
    if (!node->is_table()) s.Fail("weights", "expected a table { runout = 1, deposit = 1, ... }");
    for (const auto& [key, value] : *node->as_table())
      if (std::find(kinds.begin(), kinds.end(), std::string(key.str())) == kinds.end())
        context.Fail(&value, "objective.weights." + std::string(key.str()),
                     "no observation of this kind" + Hint(std::string(key.str()), kinds) +
                         "; the event observes " + Join(kinds));
    const Section w(context, node->as_table(), "objective.weights", kinds);
    for (const auto& [key, value] : *node->as_table()) {
      const std::string kind(key.str());
      out.objective.weights[kind] = w.Checked(
          kind, 1.0, [](double v) { return v >= 0; }, "must be >= 0");
    }
  }
  out.objective.normalise = s.Bool("normalise", true);
  out.objective.prior_weight = s.Checked(
      "prior_weight", 0.0, [](double v) { return v >= 0; }, "must be >= 0");
  // Parameters that state their own prior leave the others free unless a reference is named.
  const bool own_priors = std::any_of(out.parameters.begin(), out.parameters.end(),
                                      [](const ParameterSpec& p) { return p.prior.has_value(); });
  out.prior_reference = s.String("prior_reference", own_priors ? "none" : "table1");
  if (out.prior_reference != "table1" && out.prior_reference != "scene" &&
      out.prior_reference != "none")
    s.Fail("prior_reference",
           "'" + out.prior_reference + "': expected \"table1\", \"scene\" or \"none\"");
  if (own_priors && out.objective.prior_weight == 0 && s.Has("prior_weight"))
    s.Fail("prior_weight", kPriorNeedsWeight);
  if (out.objective.prior_weight > 0 && !own_priors && out.prior_reference == "none")
    s.Fail("prior_reference",
           "\"none\" with no parameter's own prior: prior_weight acts on nothing");
  if (out.objective.prior_weight > 0 && out.prior_reference != "none")
    out.objective.prior_reference = out.prior_reference == "scene"
                                        ? out.event.scene.scene.ground
                                        : ReferenceGround(out.event.scene.scene.ground, nullptr);
  bool any = false;
  for (const std::string& kind : kinds) {
    const auto it = out.objective.weights.find(kind);
    any = any || it == out.objective.weights.end() || it->second > 0;
  }
  if (!any) s.Fail("weights", "every kind has weight 0: nothing to fit");
}

// [solver] tolerance_m_s: the contact solve of every evaluation. When the file does not give it,
// the tighter of the default (1e-7 m/s) and the scene's own [solver] tolerance_m_s: a scene's
// looser tolerance is for its simulations, a tighter one is honoured.
void LoadSolver(const Context& context, const toml::table* table, CalibrationFile& out) {
  const Section s(context, table, "solver", {"tolerance_m_s"});
  const SceneFile& scene = out.event.scene;
  const std::vector<std::string>& given = scene.solver_keys_given;
  double& tolerance = out.objective.tolerance_m_s;
  tolerance = calibration::kCalibrationTolerance_m_s;
  out.tolerance_source = "default";
  if (std::find(given.begin(), given.end(), "tolerance_m_s") != given.end() &&
      scene.scene.options.tolerance_m_s < tolerance) {
    tolerance = scene.scene.options.tolerance_m_s;
    out.tolerance_source = "scene";
  }
  if (s.Has("tolerance_m_s")) {
    // The bounds of [solver] tolerance_m_s in scene files.
    const SolverOptionInfo& f = *FindSolverOption("tolerance_m_s");
    tolerance = s.Checked(
        "tolerance_m_s", tolerance, [&](double v) { return f.valid.Contains(v); },
        "must be in " + f.valid.Interval() + " " + f.unit +
            " (the contact solve's tolerance of every evaluation)");
    out.tolerance_source = "calibration file";
  }
}

void LoadOptimizer(const Context& context, const toml::table* table, CalibrationFile& out) {
  const Section s(context, table, "optimizer",
                  {"algorithm", "max_evaluations", "max_time_s", "ftol_rel", "ftol_abs", "xtol_abs",
                   "initial_step", "population", "starts", "start_design", "seed", "fd_step"});
  calibration::OptimizerOptions& o = out.options.optimizer;
  o.algorithm = s.String("algorithm", o.algorithm);
  const auto& names = calibration::AlgorithmNames();
  if (std::find(names.begin(), names.end(), o.algorithm) == names.end())
    s.Fail("algorithm", "unknown algorithm '" + o.algorithm + "'" + Hint(o.algorithm, names) +
                            "; known: " + Join(names));
  const long evaluations = s.Integer("max_evaluations", o.max_evaluations);
  if (evaluations < 1 || evaluations > 1000000)
    s.Fail("max_evaluations", std::to_string(evaluations) + " must be in 1 .. 1000000");
  o.max_evaluations = static_cast<int>(evaluations);
  o.max_time_s = s.Checked(
      "max_time_s", o.max_time_s, [](double v) { return v >= 0; }, "must be >= 0 (0: no limit)");
  const auto non_negative = [](double v) { return v >= 0; };
  o.ftol_rel = s.Checked("ftol_rel", o.ftol_rel, non_negative, "must be >= 0");
  o.ftol_abs = s.Checked("ftol_abs", o.ftol_abs, non_negative, "must be >= 0");
  o.xtol_abs = s.Checked("xtol_abs", o.xtol_abs, non_negative, "must be >= 0");
  o.initial_step = s.Checked(
      "initial_step", o.initial_step, [](double v) { return v > 0 && v <= 1; },
      "must be in (0, 1] (a fraction of each parameter's range)");
  const long population = s.Integer("population", 0);
  if (population < 0 || population > 100000)
    s.Fail("population", std::to_string(population) + " must be in 0 .. 100000 (0: NLopt's)");
  o.population = static_cast<int>(population);
  const long starts = s.Integer("starts", 1);
  if (starts < 1 || starts > o.max_evaluations)
    s.Fail("starts", std::to_string(starts) + " must be in 1 .. max_evaluations (" +
                         std::to_string(o.max_evaluations) + ")");
  o.starts = static_cast<int>(starts);
  o.start_design = s.String("start_design", o.start_design);
  if (o.start_design != "sobol" && o.start_design != "lhs")
    s.Fail("start_design", "'" + o.start_design + "': expected \"sobol\" or \"lhs\"");
  if (o.start_design == "sobol" && o.starts > 1 &&
      out.parameters.size() > static_cast<std::size_t>(calibration::kMaxSobolDimension))
    s.Fail("start_design", "Sobol starts take at most 16 parameters; use \"lhs\"");
  const long seed = s.Integer("seed", 1);
  if (seed < 0) s.Fail("seed", std::to_string(seed) + " must be >= 0");
  o.seed = static_cast<std::uint64_t>(seed);
  o.fd_step = s.Checked(
      "fd_step", 0.0, [](double v) { return v >= 0 && v <= 0.25; },
      "must be in [0, 0.25] (a fraction of each range; 0: measured at the start)");
  if (s.Has("fd_step") && o.algorithm != "ceres")
    s.Fail("fd_step", "only algorithm = \"ceres\" takes derivatives");
  std::string why;
  if (!o.IsValid(&why)) s.FailCheck(why);
}

void LoadRoughness(const Context& context, const toml::table* table, CalibrationFile& out) {
  const Section s(context, table, "roughness", {"enabled", "steps", "seeds", "profile_points"});
  out.options.roughness = s.Bool("enabled", true);
  if (const toml::node* node = s.Node("steps")) {
    const toml::array* array = node->as_array();
    if (!array || array->empty()) s.Fail("steps", "expected a list of steps, e.g. [1e-4, 1e-2]");
    out.options.roughness_options.steps = s.Numbers("steps", array->size());
  }
  const long seeds = s.Integer("seeds", out.options.roughness_options.seeds);
  if (seeds < 0 || seeds > 100) s.Fail("seeds", std::to_string(seeds) + " must be in 0 .. 100");
  out.options.roughness_options.seeds = static_cast<int>(seeds);
  const long points = s.Integer("profile_points", out.options.profile_options.points);
  if (points < 2 || points > 1000)
    s.Fail("profile_points", std::to_string(points) + " must be in 2 .. 1000");
  out.options.profile_options.points = static_cast<int>(points);
  std::string why;
  if (!out.options.roughness_options.IsValid(&why)) s.Fail("steps", why);
}

// [uncertainty] bootstrap*: the bootstrap over runs (calibration/bootstrap.hpp).
void LoadBootstrap(const Section& s, CalibrationFile& out) {
  calibration::BootstrapOptions& b = out.options.bootstrap_options;
  constexpr long kMax = calibration::BootstrapOptions::kMaxResamples;
  const long resamples = s.Integer("bootstrap", b.resamples);
  if (resamples != 0 && (resamples < 10 || resamples > kMax))
    s.Fail("bootstrap", std::to_string(resamples) + " must be 0 (off) or in 10 .. " +
                            std::to_string(kMax) + " (resamples, each a refit of the parameters)");
  b.resamples = static_cast<int>(resamples);
  const long evaluations = s.Integer("bootstrap_evaluations", b.refit_evaluations);
  if (evaluations < 0 || evaluations > 100000)
    s.Fail("bootstrap_evaluations",
           std::to_string(evaluations) + " must be in 0 .. 100000 (per refit; 0: 10 (n + 2))");
  b.refit_evaluations = static_cast<int>(evaluations);
  if (s.Has("bootstrap_resolution"))
    out.options.bootstrap_resolution = s.Checked(
        "bootstrap_resolution", 0.0, [](double v) { return v >= 0 && v <= 0.25; },
        "must be in [0, 0.25] (a fraction of each range; 0: the points BOBYQA asks for)");
  b.level = s.Checked(
      "bootstrap_level", b.level, [](double v) { return v > 0 && v < 1; }, "must be in (0, 1)");
  b.start_spread = s.Checked(
      "bootstrap_start_spread", b.start_spread, [](double v) { return v >= 0 && v <= 0.5; },
      "must be in [0, 0.5] (a fraction of each range; 0: every refit starts at the optimum)");
  b.seed = out.options.optimizer.seed;
  if (b.resamples > 0 && !out.options.uncertainty)
    s.Fail("bootstrap", "needs enabled = true (it is estimated with the covariance)");
  std::string why;
  if (!b.IsValid(&why)) s.FailCheck(why);
}

// [uncertainty] seeds: refits with other release seeds, combined with the bootstrap
// (calibration/seeds.hpp).
void LoadSeedRefits(const Section& s, CalibrationFile& out) {
  constexpr long kMax = calibration::SeedRefitOptions::kMaxSeeds;
  const long seeds = s.Integer("seeds", out.options.seed_options.seeds);
  if (seeds != 0 && (seeds < 2 || seeds > kMax))
    s.Fail("seeds", std::to_string(seeds) + " must be 0 (off) or in 2 .. " + std::to_string(kMax) +
                        " (refits with other release seeds; an sd needs 2)");
  out.options.seed_options.seeds = static_cast<int>(seeds);
  if (seeds > 0 && out.options.bootstrap_options.resamples == 0)
    s.Fail("seeds", "needs bootstrap (its standard error is combined with the bootstrap's)");
}

void LoadUncertainty(const Context& context, const toml::table* table, CalibrationFile& out) {
  const Section s(
      context, table, "uncertainty",
      {"enabled", "fd_step", "min_reciprocal_condition_number", "weak_fraction", "bootstrap",
       "bootstrap_evaluations", "bootstrap_resolution", "bootstrap_level",
       "bootstrap_start_spread", "seeds"});
  calibration::UncertaintyOptions& o = out.options.uncertainty_options;
  out.options.uncertainty = s.Bool("enabled", true);
  o.fd_step = s.Checked(
      "fd_step", 0.0, [](double v) { return v >= 0 && v <= 0.25; },
      "must be in [0, 0.25] (a fraction of each range; 0: the optimiser's or the roughness')");
  o.min_reciprocal_condition_number = s.Checked(
      "min_reciprocal_condition_number", o.min_reciprocal_condition_number,
      [](double v) { return v > 0 && v < 1; }, "must be in (0, 1)");
  o.weak_fraction = s.Checked(
      "weak_fraction", o.weak_fraction, [](double v) { return v > 0; }, "must be > 0");
  o.profile = out.options.profile_options;
  LoadBootstrap(s, out);
  LoadSeedRefits(s, out);
}

}  // namespace

CalibrationFile LoadCalibration(const std::string& path) {
  const Context context(path);
  const toml::table root = ParseTomlFile(path, "calibration file");
  const Section top(context, &root, "",
                    {"event", "rocks", "seed", "parameters", "objective", "solver", "optimizer",
                     "roughness", "uncertainty"});
  CalibrationFile out;
  out.path = path;
  if (!top.Has("event"))
    top.Fail("event", "missing: the event file (EVENT.toml of talus validate)");
  const std::string event = context.Resolve(top.String("event", ""));
  try {
    out.event = LoadEvent(event);
  } catch (const InputError& e) {
    throw InputError(context.Where(top.Node("event")) + ": event: " + e.what());
  }
  ensemble::ReleaseSpec& release = out.event.scene.release;
  const long rocks = top.Integer("rocks", release.rocks_per_release);
  if (rocks < 2 || rocks > 100000)
    top.Fail("rocks", std::to_string(rocks) +
                          " must be in 2 .. 100000 (rocks per run; a score "
                          "needs at least 2)");
  release.SetRocksPerRelease(rocks);
  const long seed = top.Integer("seed", static_cast<long>(release.seed));
  if (seed < 0) top.Fail("seed", std::to_string(seed) + " must be >= 0");
  release.seed = static_cast<std::uint64_t>(seed);
  if (std::string why; !release.IsValid(&why)) top.Fail("rocks", why);

  LoadParameters(context, root, out);
  LoadObjective(context, SubTable(context, root, "objective"), out);
  if (out.objective.prior_weight == 0)  // a prior without a weight, on the prior's line
    for (std::size_t k = 0; k < out.parameters.size(); ++k)
      if (out.parameters[k].prior)
        context.Fail(root["parameters"][k]["prior"].node(),
                     "parameters[" + std::to_string(k) + "].prior", kPriorNeedsWeight);
  LoadSolver(context, SubTable(context, root, "solver"), out);
  LoadOptimizer(context, SubTable(context, root, "optimizer"), out);
  LoadRoughness(context, SubTable(context, root, "roughness"), out);
  LoadUncertainty(context, SubTable(context, root, "uncertainty"), out);

  out.inputs.push_back(path);
  for (const std::string& input : out.event.inputs) out.inputs.push_back(input);
  std::ifstream in(path, std::ios::binary);
  Sha256 inputs_hash;
  inputs_hash.AddStream(in);
  out.inputs_hash = inputs_hash.Add(out.event.inputs_hash).HexDigest();

  std::ostringstream path_text;  // every number at full precision
  path_text.precision(17);
  path_text << out.event.inputs_hash << ' ' << release.rocks_per_release << ' ' << release.seed;
  for (const ParameterSpec& p : out.parameters) {
    path_text << ' ' << p.Name() << ' ' << p.lower << ' ' << p.upper << ' ' << p.UsesLog() << ' '
              << p.tie;
    if (p.prior)
      path_text << " prior " << p.prior->mean << ' ' << p.prior->sd << ' ' << p.prior->factor;
  }
  const calibration::ObjectiveOptions& ob = out.objective;
  for (const auto& [kind, weight] : ob.weights) path_text << ' ' << kind << ' ' << weight;
  path_text << ' ' << ob.normalise << ' ' << ob.prior_weight << ' ' << out.prior_reference << ' '
            << ob.tolerance_m_s;
  const calibration::OptimizerOptions& o = out.options.optimizer;
  path_text << ' ' << o.algorithm << ' ' << o.ftol_rel << ' ' << o.ftol_abs << ' ' << o.xtol_abs
            << ' ' << o.initial_step << ' ' << o.population << ' ' << o.starts << ' '
            << o.start_design << ' ' << o.seed << ' ' << o.fd_step;
  out.path_hash = Sha256Hex(path_text.str());
  return out;
}

std::vector<std::string> HoldoutRuns(const std::string& holdout,
                                     const ensemble::ReleaseSpec& release, std::uint64_t seed) {
  if (holdout.empty()) return {};
  if (release.runs.empty())
    throw InputError("--holdout: the event's scene releases no runs ([release] runs)");
  if (holdout.find_first_not_of("0123456789") == std::string::npos)
    return calibration::PickRuns(release, std::stoi(holdout), seed);
  std::vector<std::string> ids;
  std::stringstream list(holdout);
  for (std::string id; std::getline(list, id, ',');) {
    id.erase(0, id.find_first_not_of(' '));
    id.erase(id.find_last_not_of(' ') + 1);
    bool known = false;
    for (const ensemble::ReleaseRun& r : release.runs) known = known || r.id == id;
    if (!known) throw InputError("--holdout: '" + id + "' is not a run of the event's scene");
    if (std::find(ids.begin(), ids.end(), id) != ids.end())
      throw InputError("--holdout: run '" + id + "' is listed twice");
    ids.push_back(id);
  }
  if (ids.size() >= release.runs.size())
    throw InputError("--holdout: every run is held out; nothing is left to fit");
  return calibration::OtherRuns(release, calibration::OtherRuns(release, ids));  // release order
}

std::unique_ptr<calibration::CalibrationProblem> MakeCalibrationProblem(
    const CalibrationFile& file, const std::string& holdout, int folds,
    const calibration::ObjectiveOptions& objective) {
  const EventFile& event = file.event;
  calibration::HeldOutChecks checks;
  checks.seed = file.options.optimizer.seed;
  checks.holdout = HoldoutRuns(holdout, event.scene.release, checks.seed);
  if (folds > 0 && event.scene.release.runs.empty())
    throw InputError("--folds: the event's scene releases no runs ([release] runs)");
  checks.folds = folds;
  if (event.reference == "table1") checks.reference = ReferenceGround(event.scene.scene.ground, nullptr);
  return std::make_unique<calibration::CalibrationProblem>(event.scene.scene, event.scene.release,
                                                           event.observations, file.parameters,
                                                           objective, checks);
}

}  // namespace talus::io
