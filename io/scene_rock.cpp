#include <toml++/toml.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "common/csv_table.hpp"
#include "common/error.hpp"
#include "io/scene_tables.hpp"

namespace talus::io::scene_tables {
namespace {

namespace fs = std::filesystem;

// [rock] clean: `false` (no outlier removal) or { <the fields of CleanOptions> }, the defaults
// for the fields not given.
pointclouds::CleanOptions LoadClean(const Context& context, const Section& rock) {
  pointclouds::CleanOptions o;
  const toml::node* node = rock.Node("clean");
  if (!node) return o;
  if (node->is_boolean()) return *node->value<bool>() ? o : pointclouds::CleanOptions::Off();
  if (!node->is_table())
    rock.Fail("clean", "expected false or an inline table { outlier_neighbours = 16, ... }");
  const Section s(context, node->as_table(), "rock.clean",
                  {"drop_non_finite", "drop_duplicates", "outlier_neighbours", "outlier_std_ratio",
                   "outlier_spacing_ratio", "outlier_passes", "voxel_m"});
  o.drop_non_finite = s.Bool("drop_non_finite", o.drop_non_finite);
  o.drop_duplicates = s.Bool("drop_duplicates", o.drop_duplicates);
  const auto integer = [&](const std::string& key, int fallback) {
    const long v = s.Integer(key, fallback);
    if (v != static_cast<int>(v)) s.Fail(key, std::to_string(v) + " is out of range");
    return static_cast<int>(v);
  };
  o.outlier_neighbours = integer("outlier_neighbours", o.outlier_neighbours);
  o.outlier_std_ratio = s.Number("outlier_std_ratio", o.outlier_std_ratio);
  o.outlier_spacing_ratio = s.Number("outlier_spacing_ratio", o.outlier_spacing_ratio);
  o.outlier_passes = integer("outlier_passes", o.outlier_passes);
  o.voxel_m = s.Number("voxel_m", o.voxel_m);
  std::string why;
  if (!o.IsValid(&why)) s.FailCheck(why);
  return o;
}

// [rock] shape = { box = [a, b, c] } and the other built-ins, with their knobs, into `rock`.
void LoadBuiltinShape(const Context& context, const Section& s, const toml::node* shape,
                      pointclouds::RockSpec& rock) {
  const Section b(context, shape->as_table(), "rock.shape",
                  {"box", "ellipsoid", "sphere", "cylinder", "rock", "eota", "size_m", "points",
                   "roughness", "shape_seed"});
  int kinds = 0;
  for (const char* kind : {"box", "ellipsoid", "sphere", "cylinder", "rock", "eota"})
    kinds += b.Has(kind);
  if (kinds != 1)
    s.Fail("shape",
           "give exactly one of box, ellipsoid or rock ([a, b, c] in m), sphere (radius in m), "
           "cylinder ([diameter, height] in m) or eota (\"111\" or \"221\", optionally with size_m "
           "= [a, b, c])");
  auto dims = [&](const std::string& key, std::size_t n, const std::string& builtin) {
    std::vector<double> d = b.Numbers(key, n);
    for (double v : d)
      if (v <= 0) b.Fail(key, "dimensions must be > 0");
    rock.dimensions_m = d;
    rock.builtin = builtin;
  };
  if (b.Has("size_m") && !b.Has("eota")) b.Fail("size_m", "only an eota shape takes a size");
  if (b.Has("box")) dims("box", 3, "box");
  if (b.Has("ellipsoid")) dims("ellipsoid", 3, "ellipsoid");
  if (b.Has("cylinder")) dims("cylinder", 2, "cylinder");
  for (const char* knob : {"points", "roughness", "shape_seed"})
    if (b.Has(knob) && !b.Has("rock")) b.Fail(knob, "only a rock shape takes " + std::string(knob));
  if (b.Has("rock")) {
    dims("rock", 3, "rock");
    const long points = b.Integer("points", rock.points);
    if (points < 4 || points > 1000000)
      b.Fail("points", std::to_string(points) + " must be in 4 .. 1000000");
    rock.points = static_cast<int>(points);
    rock.roughness = b.Checked(
        "roughness", rock.roughness, [](double v) { return v >= 0 && v <= 0.5; },
        "must be in 0 .. 0.5");
    const long seed = b.Integer("shape_seed", 0);
    if (seed < 0) b.Fail("shape_seed", std::to_string(seed) + " must be >= 0");
    rock.shape_seed = static_cast<std::uint64_t>(seed);
  }
  if (b.Has("sphere")) {
    const double radius = b.Checked("sphere", 0, kPositive, "radius must be > 0");
    rock.builtin = "icosphere";
    rock.dimensions_m = {2 * radius};
  }
  if (b.Has("eota")) {
    const std::string kind = b.String("eota", "");
    if (kind != "111" && kind != "221")
      b.Fail("eota", "'" + kind + "': expected \"111\" or \"221\"");
    rock.builtin = "eota" + kind;
    if (b.Has("size_m")) {
      rock.dimensions_m = b.Numbers("size_m", 3);
      for (double v : rock.dimensions_m)
        if (v <= 0) b.Fail("size_m", "dimensions must be > 0");
    }
  }
}

// Builds one block's shape; errors name `where`.
std::shared_ptr<const RockShape> MakeBlockShape(const pointclouds::RockSpec& spec,
                                                const std::string& where) {
  try {
    return std::make_shared<const RockShape>(pointclouds::MakeRock(spec));
  } catch (const InputError& e) {
    throw InputError(where + ": " + e.what());
  }
}

}  // namespace

void LoadRock(const Context& context, const Section& s, SceneFile& out) {
  pointclouds::RockSpec& rock = out.rock;
  if (!s.Has("shape"))
    s.Fail("shape", "missing: a point cloud file or a built-in such as { box = [1, 1, 1] }");
  rock.density_kg_m3 = s.Checked("density_kg_m3", 2700, kPositive, "must be > 0");
  RequireWithin(s, "density_kg_m3", rock.density_kg_m3, kMinDensity_kg_m3, kMaxDensity_kg_m3,
                "kg/m3");
  if (s.Has("volume_m3") && s.Has("mass_kg"))
    s.Fail("mass_kg", "give volume_m3 or mass_kg, not both");
  if (s.Has("volume_m3")) {
    rock.volume_m3 = s.Checked("volume_m3", 0, kPositive, "must be > 0");
    RequireWithin(s, "volume_m3", *rock.volume_m3, kMinVolume_m3, kMaxVolume_m3, "m3");
  }
  if (s.Has("mass_kg")) rock.mass_kg = s.Checked("mass_kg", 0, kPositive, "must be > 0");
  const long max_vertices = s.Integer("max_vertices", 0);
  if (max_vertices != 0 && (max_vertices < 4 || max_vertices > 100000))
    s.Fail("max_vertices",
           std::to_string(max_vertices) + " must be 0 (no simplification) or in 4 .. 100000");
  rock.max_vertices = static_cast<int>(max_vertices);
  const toml::node* shape = s.Node("shape");
  if (s.Has("clean") && !shape->is_string())
    s.Fail("clean", "only a point cloud file is cleaned; the shape is a built-in");
  if (shape->is_string()) {
    rock.file = context.Resolve(s.String("shape", ""));
    if (!fs::exists(rock.file)) s.Fail("shape", "file not found: " + rock.file);
    out.inputs.push_back(rock.file);
    rock.clean = LoadClean(context, s);
  } else if (shape->is_table()) {
    LoadBuiltinShape(context, s, shape, rock);
  } else {
    s.Fail("shape", "expected a file name or a built-in such as { box = [1, 1, 1] }");
  }
  if (pointclouds::DimensionsFixSize(rock) && s.Has("volume_m3"))
    s.Fail("volume_m3",
           "the dimensions of the shape fix its volume; give mass_kg (which sets the "
           "density) or neither");
  if (pointclouds::DimensionsFixSize(rock) && s.Has("mass_kg") && s.Has("density_kg_m3"))
    s.Fail("mass_kg",
           "the dimensions of the shape and mass_kg fix the density (mass / volume); "
           "give density_kg_m3 or mass_kg, not both");
  try {
    pointclouds::RockReport report;
    out.scene.rock = pointclouds::MakeRock(rock, &report);
    out.rock_description = report.source;
    for (const std::string& warning : report.warnings)
      out.warnings.push_back(context.Where(shape) + ": rock.shape: " + warning);
  } catch (const InputError& e) {
    throw InputError(context.Where(shape) + ": rock.shape: " + e.what());
  }
  std::string why;
  if (!out.scene.rock.IsValid(&why)) s.Fail("shape", why);
  if (const std::string bad =
          OutsideBounds(out.scene.rock.volume_m3, kMinVolume_m3, kMaxVolume_m3, "m3");
      !bad.empty())
    s.Fail(s.Has("mass_kg") ? "mass_kg" : "shape", "the rock's volume " + bad);
  if (s.Bool("shape_per_rock", false)) {
    if (rock.builtin != "rock")
      s.Fail("shape_per_rock", "only a built-in rock shape has a shape of its own per rock");
    out.shape_per_rock = true;
  }
}

namespace {

const std::vector<std::string> kBlockShapes = {"box", "ellipsoid", "rock", "eota111", "eota221"};
const char* const kBlockShapesExpected =
    "expected \"box\", \"ellipsoid\", \"rock\", \"eota111\" or \"eota221\"";

bool KnownBlockShape(const std::string& name) {
  return std::find(kBlockShapes.begin(), kBlockShapes.end(), name) != kBlockShapes.end();
}

// The knobs a block's shape was made from (NaN where it has none).
ensemble::ShapeKnobs KnobsOf(const pointclouds::RockSpec& spec) {
  ensemble::ShapeKnobs knobs;
  if (spec.builtin == "rock") knobs.roughness = spec.roughness;
  if (spec.file.empty() && spec.dimensions_m.size() == 3)
    knobs.size_m = Eigen::Vector3d(spec.dimensions_m[0], spec.dimensions_m[1], spec.dimensions_m[2]);
  knobs.shape_seed = spec.shape_seed;
  return knobs;
}

// The block of `spec` with other knobs: a built-in's size, a rock's roughness and seed. The
// mass, when given, stays, so the density follows the volume; a volume outside the scene's
// bounds is an InputError, as when the block is loaded.
ensemble::ShapeMaker MakerOf(const pointclouds::RockSpec& spec) {
  return [spec](const ensemble::ShapeKnobs& knobs) {
    pointclouds::RockSpec s = spec;
    if (std::isfinite(knobs.roughness)) s.roughness = knobs.roughness;
    if (knobs.size_m.allFinite()) s.dimensions_m = {knobs.size_m.x(), knobs.size_m.y(), knobs.size_m.z()};
    s.shape_seed = knobs.shape_seed;
    std::string why;
    if (!s.IsValid(&why)) throw InputError(why);
    RockShape shape = pointclouds::MakeRock(s);
    if (std::string bad = OutsideBounds(shape.volume_m3, kMinVolume_m3, kMaxVolume_m3, "m3");
        !bad.empty())
      throw InputError("the volume " + bad);
    return shape;
  };
}

// The per-block knobs of a rock shape (`roughness`, `points`, `shape_seed`) from a [blocks.<id>]
// table or a row of the blocks file, read by `number` (nullopt when not given); errors by `fail`.
struct RockKnobs {
  std::optional<double> roughness, points, shape_seed;
};

void ApplyRockKnobs(const RockKnobs& k, pointclouds::RockSpec& spec,
                    const std::function<void(const std::string&, const std::string&)>& fail) {
  const bool rock = spec.builtin == "rock";
  if (k.roughness) {
    if (!rock) fail("roughness", "only a rock block has a roughness");
    if (!(*k.roughness >= 0 && *k.roughness <= 0.5))
      fail("roughness", TenDigits(*k.roughness) + " must be in 0 .. 0.5");
    spec.roughness = *k.roughness;
  }
  if (k.points) {
    if (!rock) fail("points", "only a rock block has points");
    if (!(*k.points >= 4 && *k.points <= 1e6) || *k.points != std::floor(*k.points))
      fail("points", TenDigits(*k.points) + " must be an integer in 4 .. 1000000");
    spec.points = static_cast<int>(*k.points);
  }
  if (k.shape_seed) {
    if (!rock) fail("shape_seed", "only a rock block has a shape seed");
    if (!(*k.shape_seed >= 0 && *k.shape_seed <= 9007199254740992.0) ||
        *k.shape_seed != std::floor(*k.shape_seed))
      fail("shape_seed", TenDigits(*k.shape_seed) + " must be an integer in 0 .. 2^53");
    spec.shape_seed = static_cast<std::uint64_t>(*k.shape_seed);
  }
}

}  // namespace

// [blocks]: named rocks that runs refer to, from a table file and/or [blocks.<id>] tables. Each is
// a scanned point cloud (`file`), or a built-in shape built from its size (`shape` of the block,
// else that of [blocks]) with, for a rock, its own roughness, points and seed. EOTA blocks keep
// the size as their bounding box and take the bevel for the volume mass_kg / density_kg_m3
// (without a mass: the standard bevel-to-side ratio).
void LoadBlocks(const Context& context, const toml::table* table, SceneFile& out) {
  if (!table) return;
  const std::vector<std::string> reserved = {
      "file",           "shape",          "points",        "roughness",          "density_kg_m3",
      "shape_per_rock", "max_vertices",   "size_variation", "roughness_variation"};
  std::vector<std::string> known = reserved;
  for (const auto& [key, node] : *table)
    if (node.is_table()) known.emplace_back(key.str());
  const Section s(context, table, "blocks", known);
  const std::string shape = s.String("shape", "box");
  if (!KnownBlockShape(shape)) s.Fail("shape", "'" + shape + "': " + kBlockShapesExpected);
  pointclouds::RockSpec base;
  base.builtin = shape;
  base.density_kg_m3 = s.Checked("density_kg_m3", 2700, kPositive, "must be > 0");
  RequireWithin(s, "density_kg_m3", base.density_kg_m3, kMinDensity_kg_m3, kMaxDensity_kg_m3,
                "kg/m3");
  const long points = s.Integer("points", base.points);
  if (points < 4 || points > 1000000)
    s.Fail("points", std::to_string(points) + " must be in 4 .. 1000000");
  base.points = static_cast<int>(points);
  base.roughness = s.Checked(
      "roughness", base.roughness, [](double v) { return v >= 0 && v <= 0.5; },
      "must be in 0 .. 0.5");
  const long max_vertices = s.Integer("max_vertices", 0);
  if (max_vertices != 0 && (max_vertices < 4 || max_vertices > 100000))
    s.Fail("max_vertices",
           std::to_string(max_vertices) + " must be 0 (no simplification) or in 4 .. 100000");
  out.shape_per_rock = s.Bool("shape_per_rock", false);
  out.shape_variation.size = s.Checked(
      "size_variation", 0.0, [](double v) { return v >= 0 && v <= 0.5; }, "must be in 0 .. 0.5");
  out.shape_variation.roughness = s.Checked(
      "roughness_variation", 0.0, [](double v) { return v >= 0 && v <= 0.25; },
      "must be in 0 .. 0.25");
  for (const char* key : {"size_variation", "roughness_variation"})
    if (s.Has(key) && !out.shape_per_rock)
      s.Fail(key, "varies the shape per rock: needs shape_per_rock = true");

  // One block: a point cloud when `file` is given, else the built-in `block_shape` of `size`.
  auto add = [&](const std::string& id, const std::string& block_shape, const std::string& file,
                 std::optional<double> mass, const std::vector<double>& size,
                 const RockKnobs& knobs, const std::string& where) {
    for (const ensemble::Block& b : out.release.blocks)
      if (b.id == id) throw InputError(where + ": block '" + id + "' is defined twice");
    pointclouds::RockSpec spec = base;
    if (file.empty()) {
      spec.builtin = block_shape;
      spec.dimensions_m = size;
    } else {
      spec.builtin.clear();
      spec.file = file;
      spec.max_vertices = static_cast<int>(max_vertices);
      out.inputs.push_back(file);
    }
    spec.mass_kg = mass;
    ApplyRockKnobs(knobs, spec, [&](const std::string& key, const std::string& why) {
      throw InputError(where + ": block '" + id + "': " + key + ": " + why);
    });
    out.block_specs.push_back(spec);
    auto made = MakeBlockShape(spec, where);
    if (const std::string bad = OutsideBounds(made->volume_m3, kMinVolume_m3, kMaxVolume_m3, "m3");
        !bad.empty())
      throw InputError(where + ": block '" + id + "': the volume " + bad);
    ensemble::Block block{id, std::move(made), KnobsOf(spec), {}};
    if (file.empty()) block.make = MakerOf(spec);
    out.release.blocks.push_back(std::move(block));
  };
  if (s.Has("file")) {
    const std::string path = context.Resolve(s.String("file", ""));
    if (!fs::exists(path)) s.Fail("file", "file not found: " + path);
    out.inputs.push_back(path);
    const CsvTable rows = CsvTable::Read(path);
    rows.Require({"block_id"});
    if (!rows.Has("file")) rows.Require({"size_x_m", "size_y_m", "size_z_m"});
    const fs::path folder = fs::path(path).parent_path();
    for (int k = 0; k < rows.rows(); ++k) {
      const std::string id = rows.Text(k, "block_id");
      if (id.empty()) throw InputError(rows.Where(k, "block_id") + ": empty");
      std::string file;
      if (!rows.Empty(k, "file")) {
        file = (folder / rows.Text(k, "file")).lexically_normal().string();
        if (!fs::exists(file)) throw InputError(rows.Where(k, "file") + ": file not found: " + file);
        for (const char* c : {"size_x_m", "size_y_m", "size_z_m", "shape"})
          if (!rows.Empty(k, c))
            throw InputError(rows.Where(k, c) + ": a point cloud block takes its shape and size "
                                                "from the file; leave this cell empty");
      }
      std::vector<double> size;
      if (file.empty())
        for (const char* c : {"size_x_m", "size_y_m", "size_z_m"}) {
          size.push_back(rows.Number(k, c));
          if (size.back() <= 0) throw InputError(rows.Where(k, c) + ": must be > 0");
        }
      const std::optional<double> mass = rows.OptionalNumber(k, "mass_kg");
      if (mass && *mass <= 0) throw InputError(rows.Where(k, "mass_kg") + ": must be > 0");
      const std::string block_shape = rows.Empty(k, "shape") ? shape : rows.Text(k, "shape");
      if (!KnownBlockShape(block_shape))
        throw InputError(rows.Where(k, "shape") + ": '" + block_shape + "': " +
                         kBlockShapesExpected);
      RockKnobs knobs{rows.OptionalNumber(k, "roughness"), rows.OptionalNumber(k, "points"),
                      rows.OptionalNumber(k, "shape_seed")};
      add(id, block_shape, file, mass, size, knobs, rows.Where(k, "block_id"));
    }
  }
  for (const auto& [key, node] : *table) {
    if (!node.is_table()) continue;
    const std::string id(key.str());
    const Section b(context, node.as_table(), "blocks." + id,
                    {"mass_kg", "size_m", "shape", "file", "roughness", "points", "shape_seed"});
    std::string file;
    if (b.Has("file")) {
      for (const char* k : {"size_m", "shape"})
        if (b.Has(k))
          b.Fail(k, "a point cloud block takes its shape and size from its file");
      file = context.Resolve(b.String("file", ""));
      if (!fs::exists(file)) b.Fail("file", "file not found: " + file);
    } else if (!b.Has("size_m")) {
      b.Fail("size_m", "missing: the block's size [x, y, z] in m (or a point cloud `file`)");
    }
    std::vector<double> size;
    if (file.empty()) {
      size = b.Numbers("size_m", 3);
      for (double v : size)
        if (v <= 0) b.Fail("size_m", "dimensions must be > 0");
    }
    std::optional<double> mass;
    if (b.Has("mass_kg")) mass = b.Checked("mass_kg", 0, kPositive, "must be > 0");
    const std::string block_shape = b.String("shape", shape);
    if (!KnownBlockShape(block_shape))
      b.Fail("shape", "'" + block_shape + "': " + kBlockShapesExpected);
    RockKnobs knobs;
    if (b.Has("roughness")) knobs.roughness = b.Number("roughness", 0);
    if (b.Has("points")) knobs.points = static_cast<double>(b.Integer("points", 0));
    if (b.Has("shape_seed")) knobs.shape_seed = static_cast<double>(b.Integer("shape_seed", 0));
    add(id, block_shape, file, mass, size, knobs, context.Where(&node) + ": blocks." + id);
  }
  if (out.release.blocks.empty())
    context.Fail(table, "blocks", "no block: give a file or [blocks.<id>] tables");
  // Knobs of the random rock shape need rock blocks.
  const auto is_rock = [](const pointclouds::RockSpec& b) { return b.builtin == "rock"; };
  const bool all_rocks = std::all_of(out.block_specs.begin(), out.block_specs.end(), is_rock);
  const bool any_rock = std::any_of(out.block_specs.begin(), out.block_specs.end(), is_rock);
  if ((s.Has("points") || s.Has("roughness")) && !any_rock)
    s.Fail(s.Has("points") ? "points" : "roughness", "only rock blocks take points and roughness");
  if (s.Has("max_vertices") &&
      std::none_of(out.block_specs.begin(), out.block_specs.end(),
                   [](const pointclouds::RockSpec& b) { return !b.file.empty(); }))
    s.Fail("max_vertices", "only point cloud blocks (file) are simplified");
  if (out.shape_per_rock && !all_rocks)
    s.Fail("shape_per_rock", "only rock blocks have a shape of their own per rock");
}

}  // namespace talus::io::scene_tables

namespace talus::io {

ensemble::ShapeKnobs VariedKnobs(const ensemble::ShapeKnobs& knobs, const ShapeVariation& v,
                                 std::uint64_t seed) {
  // Uniform draws in [0, 1) from a stream of the seed's own (53 bits of SplitMix64 outputs),
  // apart from the one that places the hull's points.
  const std::uint64_t stream = seed ^ 0x5851F42D4C957F2DULL;
  const auto uniform = [&](std::uint64_t i) {
    return double(pointclouds::ShapeSeed(stream, i) >> 11) * 0x1p-53;
  };
  ensemble::ShapeKnobs out = knobs;
  if (v.size > 0 && knobs.size_m.allFinite()) {
    // Each axis by exp(a (2U - 1)), over the factors' geometric mean: the axis ratios vary, the
    // product of the axes (so the volume of the envelope, and with a mass the density) does not.
    Eigen::Vector3d log_factor;
    for (int i = 0; i < 3; ++i) log_factor[i] = v.size * (2 * uniform(std::uint64_t(i)) - 1);
    log_factor.array() -= log_factor.mean();
    out.size_m = knobs.size_m.cwiseProduct(log_factor.array().exp().matrix());
  }
  if (v.roughness > 0 && std::isfinite(knobs.roughness))
    out.roughness = std::clamp(knobs.roughness + v.roughness * (2 * uniform(3) - 1), 0.0, 0.5);
  return out;
}

}  // namespace talus::io
