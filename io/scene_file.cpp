#include "io/scene_file.hpp"

#include <toml++/toml.h>

#include <algorithm>
#include <fstream>

#include "common/closest_name.hpp"
#include "common/error.hpp"
#include "common/format.hpp"
#include "common/sha256.hpp"
#include "io/scene_tables.hpp"
#include "io/toml_section.hpp"

// The driver (LoadScene) and the [ground], [solver] and [output] tables; the other tables are read
// in their own files (scene_tables.hpp).
namespace talus::io {
namespace {

using scene_tables::kPositive;
using scene_tables::RequireWithin;

// The keys of a [ground.<name>] table: code, model and every field of kGroundFields.
std::vector<std::string> GroundKeys() {
  std::vector<std::string> keys = {"code", "model"};
  for (const GroundFieldInfo& f : kGroundFields) keys.emplace_back(f.key);
  return keys;
}

// [ground.<name>]: user categories, or overrides of built-in ones.
void LoadGround(const Context& context, const toml::table* ground, GroundTable& table) {
  if (!ground) return;
  const std::vector<std::string> builtin(GroundTable::BuiltInNames().begin(),
                                         GroundTable::BuiltInNames().end());
  for (const auto& [key, node] : *ground) {
    const std::string name(key.str());
    if (!node.is_table())
      context.Fail(&node, "ground." + name, "expected a table ([ground." + name + "])");
    const Section s(context, node.as_table(), "ground." + name, GroundKeys());
    const int existing = table.IndexOfName(name);
    GroundCategory category;
    category.name = name;
    if (existing >= 0) {
      category = table.category(existing);
    } else {
      const std::string hint = ClosestName(name, builtin);
      for (const char* required : {"code", "mu_min", "mu_max", "beta", "kappa", "nu"})
        if (!s.Has(required))
          s.Fail(
              required,
              std::string(
                  "missing: a new ground category needs code, mu_min, mu_max, beta, kappa and nu") +
                  (hint.empty() ? "" : " (or did you mean the built-in '" + hint + "'?)"));
    }
    const long code = s.Integer("code", category.code);
    if (code < 0 || code > 254) s.Fail("code", std::to_string(code) + " must be in 0..254");
    category.code = static_cast<int>(code);
    GroundParams& p = category.params;
    if (s.Has("model")) {
      const std::string model = s.String("model", "");
      if (!ParseGroundModel(model, &p.model))
        s.Fail("model", "unknown ground model '" + model + "'; known: " + kGroundModelNames.List());
    }
    for (const GroundFieldInfo& f : kGroundFields) {
      p.*f.member = s.Number(f.key, p.*f.member);
      if (f.group == GroundFieldInfo::Group::kSoil && s.Has(f.key) && !p.IsSoil())
        s.Fail(f.key, std::string(f.key) + " acts only in a category with model = \"lu2019\"");
    }
    std::string why;
    if (!p.IsValid(&why)) s.FailCheck(why);
    const int other = table.IndexOfCode(category.code);
    if (other >= 0 && table.category(other).name != name)
      s.Fail("code",
             std::to_string(code) + " is already the code of '" + table.category(other).name + "'");
    table.Set(category);
  }
  if (table.size() > GroundGrid::kNoGround)
    context.Fail(ground, "ground", "too many ground categories");
}

// SHA-256 of `before` and then of the files' contents, in order.
std::string HashFiles(const std::vector<std::string>& files, const std::string& before) {
  Sha256 hash;
  hash.Add(before);
  for (const std::string& f : files) {
    std::ifstream in(f, std::ios::binary);
    hash.AddStream(in);
  }
  return hash.HexDigest();
}

// "unknown <what> 'name' (did you mean '...'?); known: a, b, c".
std::string UnknownName(const std::string& name, const EnumNames& names) {
  const std::vector<std::string> known(names.names.begin(), names.names.end());
  const std::string hint = ClosestName(name, known);
  return "unknown " + std::string(names.what) + " '" + name + "'" +
         (hint.empty() ? "" : " (did you mean '" + hint + "'?)") + "; known: " + names.List();
}

// A key naming one value of an enum: its number, or an error naming the known names and the
// closest one.
int Choice(const Section& s, const std::string& key, const EnumNames& names) {
  const std::string name = s.String(key, "");
  const int value = names.Find(name);
  if (value >= 0) return value;
  s.Fail(key, UnknownName(name, names));
}

// The value [solver] gives for option `f` (the key is there), as SolverOptionInfo::Member sets it.
double SolverValue(const Section& s, const SolverOptionInfo& f) {
  switch (f.type) {
    case SolverOptionInfo::Type::kNumber: {
      const double v = s.Number(f.key, 0);
      if (f.HasPlausibleRange())
        RequireWithin(s, f.key, v, f.plausible_lower, f.plausible_upper, f.unit);
      return v;
    }
    case SolverOptionInfo::Type::kInteger: {
      const long v = s.Integer(f.key, 0);
      if (v != static_cast<int>(v))
        s.Fail(f.key, std::to_string(v) + " is out of range (" + TenDigits(f.valid.lower) + " .. " +
                          TenDigits(f.valid.upper) + ")");
      return static_cast<double>(v);
    }
    case SolverOptionInfo::Type::kChoice:
      return Choice(s, f.key, *f.choices);
  }
  return 0;
}

// The keys of [solver]: preset and every key of kSolverOptions.
std::vector<std::string> SolverKeys() {
  std::vector<std::string> keys = {"preset", "self_check"};
  for (const SolverOptionInfo& f : kSolverOptions) keys.emplace_back(f.key);
  return keys;
}

void LoadSolver(const Section& s, SolverOptions& o, SolverPreset& preset,
                std::vector<std::string>& given) {
  // The preset sets the accuracy knobs' defaults; keys given here override them.
  if (s.Has("preset")) preset = static_cast<SolverPreset>(Choice(s, "preset", kSolverPresetNames));
  ApplyPreset(preset, &o);
  for (const SolverOptionInfo& f : kSolverOptions) {
    if (!s.Has(f.key)) continue;
    if (f.preset_knob) given.emplace_back(f.key);
    f.member.set(o, SolverValue(s, f));
  }
  // One coefficient (SolverOptions): the tangential one follows the normal one unless given.
  if (!s.Has("tangential_restitution")) o.tangential_restitution = o.normal_restitution;
  // Newton's law keeps whole steps: the sub-steps' default gives way to a restitution, and a
  // scene that asks for both is told so rather than silently given whole steps.
  if (o.normal_restitution > 0) {
    if (s.Has("impact_substeps") && o.impact_substeps > 1)
      s.FailCheck("impact_substeps = " + std::to_string(o.impact_substeps) +
                  " needs normal_restitution = 0 (Newton's law takes the begin velocities of a "
                  "whole step; it is " +
                  RoundTrip(o.normal_restitution) + ")");
    o.impact_substeps = 1;
    // Nor does it hold contacts: it would rebound a held vertex from above the terrain.
    if (s.Has("contact_hold") && o.contact_hold == ContactHold::kHeld)
      s.FailCheck("contact_hold = \"held\" needs normal_restitution = 0 (Newton's law would "
                  "rebound a held vertex from above the terrain; it is " +
                  RoundTrip(o.normal_restitution) + ")");
    o.contact_hold = ContactHold::kMidpoint;
  }
  // Every impact in sub-steps needs sub-steps, and held contacts: without them a pivot that a
  // step leaves free comes back in the next as a new contact, and the step is split for it.
  if (s.Has("substep_impacts") && o.substep_impacts == SubstepImpacts::kAll) {
    if (o.normal_restitution > 0)
      s.FailCheck(
          "substep_impacts = \"all\" needs normal_restitution = 0 (Newton's law keeps "
          "whole steps; it is " +
          RoundTrip(o.normal_restitution) + ")");
    if (o.impact_substeps == 1)
      s.FailCheck("substep_impacts = \"all\" needs impact_substeps > 1 (it is 1: whole steps)");
    if (o.contact_hold != ContactHold::kHeld)
      s.FailCheck(
          "substep_impacts = \"all\" needs contact_hold = \"held\" (without it a pivot "
          "that a step leaves free would come back as a new contact and split the next)");
  }
  std::string why;
  if (!o.IsValid(&why)) s.FailCheck(why);
}

void LoadOutput(const Section& s, OutputSpec& o) {
  o.trajectories = s.Bool("trajectories", o.trajectories);
  o.trajectory_interval_s =
      s.Checked("trajectory_interval_s", o.trajectory_interval_s, kPositive, "must be > 0");
  o.quicklook = s.Bool("quicklook", o.quicklook);
  o.report = s.Bool("report", o.report);
  o.geopackage = s.Bool("geopackage", o.geopackage);
  if (const toml::node* node = s.Node("rasters")) {
    const toml::array* array = node->as_array();
    if (!array) s.Fail("rasters", "expected a list of raster names");
    for (const toml::node& item : *array) {
      const auto name = item.value<std::string>();
      if (!name || !item.is_string())
        s.Fail("rasters", "expected a list of raster names (strings)");
      ensemble::RasterKind kind;
      if (!ensemble::kRasterKindNames.Parse(*name, &kind))
        s.Fail("rasters", UnknownName(*name, ensemble::kRasterKindNames));
      if (std::find(o.rasters.begin(), o.rasters.end(), kind) == o.rasters.end())
        o.rasters.push_back(kind);
    }
  }
  if (const toml::node* node = s.Node("percentiles")) {
    const toml::array* array = node->as_array();
    if (!array) s.Fail("percentiles", "expected a list of integer percents in 1 .. 99");
    o.percentiles.clear();
    for (const toml::node& item : *array) {
      if (!item.is_integer())
        s.Fail("percentiles", "expected a list of integer percents in 1 .. 99 (e.g. [50, 95])");
      const std::int64_t p = *item.value<std::int64_t>();
      if (p < 1 || p > 99) s.Fail("percentiles", std::to_string(p) + " is out of range (1 .. 99)");
      o.percentiles.push_back(static_cast<int>(p));
    }
    std::sort(o.percentiles.begin(), o.percentiles.end());
    o.percentiles.erase(std::unique(o.percentiles.begin(), o.percentiles.end()),
                        o.percentiles.end());
  }
  if (s.Has("raster_format"))
    o.raster_format = static_cast<RasterFormat>(Choice(s, "raster_format", kRasterFormatNames));
}

}  // namespace

void UseSolverPreset(SceneFile& scene, SolverPreset preset) {
  SolverOptions o = scene.scene.options;
  ApplyPreset(preset, &o);
  // --preset wins over the scene's own knobs; each value it changes is named.
  scene.solver_keys_overridden.clear();
  for (const std::string& key : scene.solver_keys_given) {
    const SolverOptionInfo* f = FindSolverOption(key);
    const double was = f->member.get(scene.scene.options), now = f->member.get(o);
    if (was != now)
      scene.solver_keys_overridden.push_back(key + " = " + RoundTrip(was) + " -> " +
                                             RoundTrip(now));
  }
  scene.scene.options = o;
  scene.solver_preset = preset;
  scene.solver_preset_from_command_line = true;
}

ensemble::RasterRequest OutputSpec::Request(const GridGeometry& grid) const {
  ensemble::RasterRequest r;
  r.grid = grid;
  for (ensemble::RasterKind kind : rasters) r.Wants(kind) = true;
  r.percentiles = percentiles;
  return r;
}

namespace {

// The scene of a parsed scene file `path` (which need not exist when `text` holds its contents).
SceneFile LoadSceneTable(const toml::table& root, const std::string& path,
                         const std::string* text) {
  const Context context(path);
  const Section top(context, &root, "",
                    {"terrain", "ground", "rock", "blocks", "release", "evaluation_lines",
                     "barriers", "forest", "solver", "output"});
  for (const char* required : {"terrain", "release"})
    if (!root.get(required))
      context.Fail(nullptr, required, std::string("missing table [") + required + "]");
  if (!root.get("rock") && !root.get("blocks"))
    context.Fail(nullptr, "rock", "missing table [rock] (or [blocks] for a run table)");

  SceneFile out;
  out.path = path;
  if (!text) out.inputs.push_back(path);
  LoadGround(context, SubTable(context, root, "ground"), out.scene.ground);
  scene_tables::LoadTerrain(
      context,
      Section(context, SubTable(context, root, "terrain"), "terrain",
              {"dem", "plane", "ground", "ground_polygons", "default_ground"}),
      out);
  scene_tables::LoadBlocks(context, SubTable(context, root, "blocks"), out);
  out.has_rock = root.get("rock") != nullptr;
  if (out.has_rock) {
    scene_tables::LoadRock(context,
                           Section(context, SubTable(context, root, "rock"), "rock",
                                   {"shape", "density_kg_m3", "volume_m3", "mass_kg",
                                    "max_vertices", "shape_per_rock", "clean"}),
                           out);
  } else {
    out.scene.rock = *out.release.blocks.front().shape;  // the shape of runs' first block
    out.rock_description = "blocks (" + std::to_string(out.release.blocks.size()) + ")";
  }
  scene_tables::LoadRelease(
      context,
      Section(context, SubTable(context, root, "release"), "release",
              {"points", "lines", "polygons", "file", "layer", "where", "runs", "single_impacts",
               "block_column", "ground_z_tolerance_m", "height_m", "height_reference", "rocks",
               "rocks_per_m2",
               "rocks_per_cell", "clip_to_dem", "orientation", "velocity_m_s",
               "angular_velocity_rad_s", "seed", "volume", "source"}),
      out);
  scene_tables::LoadEvaluationLines(
      context,
      Section(context, SubTable(context, root, "evaluation_lines"), "evaluation_lines",
              {"lines", "names", "file", "name_field"}),
      out);
  scene_tables::LoadBarriers(context, root.get("barriers"), out);
  scene_tables::LoadForest(context,
                           Section(context, SubTable(context, root, "forest"), "forest",
                                   {"model", "trees", "dbh_field", "species_field", "stands",
                                    "stands_file", "stems_per_ha_raster", "dbh_raster",
                                    "raster_species", "stem_height_m", "friction",
                                    "energy_coefficient_j", "energy_exponent", "species", "seed"}),
                           root.get("forest") != nullptr, out);
  const Section solver(context, SubTable(context, root, "solver"), "solver", SolverKeys());
  LoadSolver(solver, out.scene.options, out.solver_preset, out.solver_keys_given);
  // A run's own check of its time step (talus simulate --self-check N): 0, or 2 .. the run's rocks
  // (checked by the command, which knows the rocks after its --rocks).
  out.self_check = solver.Integer("self_check", 0);
  if (out.self_check != 0 && out.self_check < 2)
    solver.Fail("self_check", std::to_string(out.self_check) + " must be 0 (none) or >= 2 rocks");
  const Section output(context, SubTable(context, root, "output"), "output",
                       {"trajectories", "trajectory_interval_s", "rasters", "percentiles",
                        "raster_format", "quicklook", "report", "geopackage"});
  LoadOutput(output, out.output);
  if (!out.has_forest && std::count(out.output.rasters.begin(), out.output.rasters.end(),
                                    ensemble::RasterKind::kTreeHits) > 0)
    output.Fail("rasters",
                out.forest_model == "drag"
                    ? "tree_hits counts the impacts on explicit stems: [forest] model "
                      "= \"drag\" has none"
                    : "tree_hits counts the impacts on stems: the scene has no [forest]");
  if (!out.release.blocks.empty() && out.release.runs.empty())
    context.Fail(root.get("blocks"), "blocks",
                 "blocks are for the runs of a run table ([release] runs = \"file.csv\")");
  if (out.shape_per_rock) {
    // Each rock its own seeded shape: of its run's block (with the block's knobs as the release
    // holds them, which a calibration may change), or of the scene's rock.
    const pointclouds::RockSpec rock = out.rock;
    const ShapeVariation variation = out.shape_variation;
    out.release.shape_per_rock = [rock, variation](const ensemble::Block* block,
                                                   std::uint64_t seed) {
      if (!block) {
        pointclouds::RockSpec spec = rock;
        spec.shape_seed = seed;
        return pointclouds::MakeRock(spec);
      }
      ensemble::ShapeKnobs knobs = VariedKnobs(block->knobs, variation, seed);
      knobs.shape_seed = seed;
      try {
        return block->make(knobs);
      } catch (const InputError& e) {
        throw InputError("block '" + block->id + "', the shape of shape seed " +
                         std::to_string(seed) + ": " + e.what());
      }
    };
  }
  std::string why;
  if (!out.scene.IsValid(&why)) throw InputError(path + ": " + why);
  // A scene given as text: its text first, then the files it read.
  out.inputs_hash = HashFiles(out.inputs, text ? *text : std::string());
  return out;
}

}  // namespace

SceneFile LoadScene(const std::string& path) {
  return LoadSceneTable(ParseTomlFile(path, "scene file"), path, nullptr);
}

SceneFile LoadSceneText(const std::string& text, const std::string& path) {
  toml::table root;
  try {
    root = toml::parse(text, path);
  } catch (const toml::parse_error& e) {
    throw InputError(path + ":" + std::to_string(e.source().begin.line) +
                     ": TOML syntax error: " + std::string(e.description()));
  }
  return LoadSceneTable(root, path, &text);
}

}  // namespace talus::io
