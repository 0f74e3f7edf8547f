#include "io/scene_file.hpp"

#include <toml++/toml.h>

#include <algorithm>
#include <cstdio>
#include <fstream>

#include "common/closest_name.hpp"
#include "common/error.hpp"
#include "io/scene_tables.hpp"
#include "io/toml_section.hpp"

// The driver (LoadScene) and the [ground], [solver] and [output] tables; the other tables are read
// in their own files (scene_tables.hpp).
namespace talus::io {
namespace {

using scene_tables::kMaxGravity_m_s2;
using scene_tables::kMinGravity_m_s2;
using scene_tables::kPositive;
using scene_tables::RequireWithin;

const std::vector<std::string> kRasterNames = {"speed",    "energy",   "jump_height",
                                               "passages", "deposits", "reach_probability"};

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
          s.Fail(required,
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
        s.Fail("model", "unknown ground model '" + model + "'; known: hard, lu2019");
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

std::string Hex(std::uint64_t v) {
  char buffer[17];
  std::snprintf(buffer, sizeof buffer, "%016llx", static_cast<unsigned long long>(v));
  return buffer;
}

std::string HashFiles(const std::vector<std::string>& files) {
  std::uint64_t h = 1469598103934665603ULL;
  for (const std::string& f : files) {
    std::ifstream in(f, std::ios::binary);
    char buffer[65536];
    while (in.read(buffer, sizeof buffer) || in.gcount() > 0) {
      for (std::streamsize k = 0; k < in.gcount(); ++k) {
        h ^= static_cast<unsigned char>(buffer[k]);
        h *= 1099511628211ULL;
      }
    }
  }
  return Hex(h);
}

// A key naming one value of an enum: parsed by `parse` into *out when given; else an error naming
// the known names and the closest one.
template <class Enum>
void Choice(const Section& s, const std::string& key, const std::string& what,
            const std::vector<std::string>& known, bool (*parse)(std::string_view, Enum*),
            Enum* out) {
  if (!s.Has(key)) return;
  const std::string name = s.String(key, "");
  if (parse(name, out)) return;
  const std::string hint = ClosestName(name, known);
  std::string list;
  for (const std::string& k : known) list += (list.empty() ? "" : ", ") + k;
  s.Fail(key, "unknown " + what + " '" + name + "'" +
                  (hint.empty() ? "" : " (did you mean '" + hint + "'?)") + "; known: " + list);
}

void LoadSolver(const Section& s, SolverOptions& o, SolverPreset& preset,
                std::vector<std::string>& given) {
  // The preset sets the accuracy knobs' defaults; keys given here override them.
  if (s.Has("preset")) {
    const std::string name = s.String("preset", "");
    if (!ParseSolverPreset(name, &preset)) {
      const std::string hint = ClosestName(name, {"fast", "default", "accurate"});
      s.Fail("preset", "unknown preset '" + name + "'" +
                           (hint.empty() ? "" : " (did you mean '" + hint + "'?)") +
                           "; known: fast, default, accurate");
    }
  }
  ApplyPreset(preset, &o);
  for (const char* key : {"dt_s", "tolerance_m_s", "max_iterations"})
    if (s.Has(key)) given.push_back(key);
  o.dt_s = s.Number("dt_s", o.dt_s);
  o.max_time_s = s.Number("max_time_s", o.max_time_s);
  o.gravity_m_s2 = s.Number("gravity_m_s2", o.gravity_m_s2);
  RequireWithin(s, "gravity_m_s2", o.gravity_m_s2, kMinGravity_m_s2, kMaxGravity_m_s2, "m/s2");
  o.normal_restitution = s.Number("normal_restitution", o.normal_restitution);
  // One coefficient (SolverOptions): the tangential one follows the normal one unless given.
  o.tangential_restitution = s.Number("tangential_restitution", o.normal_restitution);
  Choice(s, "viscous", "reading", {"centre_of_mass", "contact_friction"}, ParseViscousReading,
         &o.viscous);
  Choice(s, "contact_solve", "method", {"gauss_seidel", "block"}, ParseContactSolveMethod,
         &o.contact_solve);
  Choice(s, "predicted_lever", "lever", {"midpoint", "touch"}, ParsePredictedLever,
         &o.predicted_lever);
  Choice(s, "soil_drag", "drag point", {"centre_of_mass", "submerged_centroid"},
         ParseSoilDragPoint, &o.soil_drag);
  o.tolerance_m_s = s.Number("tolerance_m_s", o.tolerance_m_s);
  const long max_iterations = s.Integer("max_iterations", o.max_iterations);
  if (max_iterations != static_cast<int>(max_iterations))
    s.Fail("max_iterations", std::to_string(max_iterations) + " is out of range (1 .. 100000)");
  o.max_iterations = static_cast<int>(max_iterations);
  o.prox_alpha = s.Number("prox_alpha", o.prox_alpha);
  o.rest_speed_m_s = s.Number("rest_speed_m_s", o.rest_speed_m_s);
  o.rest_angular_speed_rad_s = s.Number("rest_angular_speed_rad_s", o.rest_angular_speed_rad_s);
  o.rest_hold_s = s.Number("rest_hold_s", o.rest_hold_s);
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
      if (std::find(kRasterNames.begin(), kRasterNames.end(), *name) == kRasterNames.end()) {
        const std::string hint = ClosestName(*name, kRasterNames);
        s.Fail("rasters",
               "unknown raster '" + *name + "'" +
                   (hint.empty() ? "" : " (did you mean '" + hint + "'?)") +
                   "; known: speed, energy, jump_height, passages, deposits, reach_probability");
      }
      if (std::find(o.rasters.begin(), o.rasters.end(), *name) == o.rasters.end())
        o.rasters.push_back(*name);
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
  if (s.Has("raster_format")) {
    const std::string name = s.String("raster_format", "");
    if (name == "gtiff") {
      o.raster_format = RasterFormat::kGeoTiff;
    } else if (name == "cog") {
      o.raster_format = RasterFormat::kCog;
    } else {
      const std::string hint = ClosestName(name, {"gtiff", "cog"});
      s.Fail("raster_format", "unknown format '" + name + "'" +
                                  (hint.empty() ? "" : " (did you mean '" + hint + "'?)") +
                                  "; known: gtiff, cog");
    }
  }
}

}  // namespace

void UseSolverPreset(SceneFile& scene, SolverPreset preset) {
  SolverOptions o = scene.scene.options;
  ApplyPreset(preset, &o);
  const SolverOptions& given = scene.scene.options;
  scene.solver_keys_overridden.clear();
  const auto note = [&](const std::string& key, double was, double now) {
    const bool scene_gives = std::find(scene.solver_keys_given.begin(),
                                       scene.solver_keys_given.end(),
                                       key) != scene.solver_keys_given.end();
    if (scene_gives && was != now)
      scene.solver_keys_overridden.push_back(key + " = " + scene_tables::Fmt(was) + " -> " +
                                             scene_tables::Fmt(now));
  };
  note("dt_s", given.dt_s, o.dt_s);
  note("tolerance_m_s", given.tolerance_m_s, o.tolerance_m_s);
  note("max_iterations", given.max_iterations, o.max_iterations);
  scene.scene.options = o;
  scene.solver_preset = preset;
  scene.solver_preset_from_command_line = true;
}

ensemble::RasterRequest OutputSpec::Request(const GridGeometry& grid) const {
  ensemble::RasterRequest r;
  r.grid = grid;
  auto has = [&](const char* name) {
    return std::find(rasters.begin(), rasters.end(), name) != rasters.end();
  };
  r.speed = has("speed");
  r.energy = has("energy");
  r.jump_height = has("jump_height");
  r.passages = has("passages");
  r.deposits = has("deposits");
  r.reach_probability = has("reach_probability");
  r.percentiles = percentiles;
  return r;
}

SceneFile LoadScene(const std::string& path) {
  const Context context(path);
  const toml::table root = ParseTomlFile(path, "scene file");
  const Section top(
      context, &root, "",
      {"terrain", "ground", "rock", "blocks", "release", "evaluation_lines", "solver", "output"});
  for (const char* required : {"terrain", "release"})
    if (!root.get(required))
      context.Fail(nullptr, required, std::string("missing table [") + required + "]");
  if (!root.get("rock") && !root.get("blocks"))
    context.Fail(nullptr, "rock", "missing table [rock] (or [blocks] for a run table)");

  SceneFile out;
  out.path = path;
  out.inputs.push_back(path);
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
               "block_column", "height_m", "height_reference", "rocks", "rocks_per_m2",
               "rocks_per_cell", "clip_to_dem", "orientation", "velocity_m_s",
               "angular_velocity_rad_s", "seed"}),
      out);
  scene_tables::LoadEvaluationLines(
      context,
      Section(context, SubTable(context, root, "evaluation_lines"), "evaluation_lines",
              {"lines", "names", "file", "name_field"}),
      out);
  LoadSolver(Section(context, SubTable(context, root, "solver"), "solver",
                     {"preset", "dt_s", "max_time_s", "gravity_m_s2", "normal_restitution",
                      "tangential_restitution", "viscous", "contact_solve", "predicted_lever",
                      "soil_drag", "tolerance_m_s", "max_iterations", "prox_alpha",
                      "rest_speed_m_s", "rest_angular_speed_rad_s", "rest_hold_s"}),
             out.scene.options, out.solver_preset, out.solver_keys_given);
  LoadOutput(Section(context, SubTable(context, root, "output"), "output",
                     {"trajectories", "trajectory_interval_s", "rasters", "percentiles",
                      "raster_format", "quicklook", "report", "geopackage"}),
             out.output);
  if (!out.release.blocks.empty() && out.release.runs.empty())
    context.Fail(root.get("blocks"), "blocks",
                 "blocks are for the runs of a run table ([release] runs = \"file.csv\")");
  if (out.shape_per_rock) {
    // Each rock its own seeded shape, from its run's block (or the scene's rock).
    const std::vector<pointclouds::RockSpec> blocks = out.block_specs;
    const pointclouds::RockSpec rock = out.rock;
    out.release.shape_per_rock = [blocks, rock](int block, std::uint64_t seed) {
      pointclouds::RockSpec spec = block >= 0 ? blocks[static_cast<std::size_t>(block)] : rock;
      spec.shape_seed = seed;
      return pointclouds::MakeRock(spec);
    };
  }
  std::string why;
  if (!out.scene.IsValid(&why)) throw InputError(path + ": " + why);
  out.inputs_hash = HashFiles(out.inputs);
  return out;
}

}  // namespace talus::io
