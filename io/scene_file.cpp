#include "io/scene_file.hpp"

#include <toml++/toml.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "common/closest_name.hpp"
#include "common/csv_table.hpp"
#include "common/error.hpp"
#include "fieldobs/single_impacts.hpp"
#include "io/raster.hpp"
#include "io/toml_section.hpp"
#include "io/vector.hpp"

namespace talus::io {
namespace {

namespace fs = std::filesystem;
using ensemble::ReleaseGeometry;

const std::vector<std::string> kRasterNames = {"speed",    "energy",   "jump_height",
                                               "passages", "deposits", "reach_probability"};

std::string Fmt(double v) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.10g", v);
  return buffer;
}

const auto kPositive = [](double v) { return v > 0; };

// Bounds of plausible input (docs/scenes.md): finite values beyond them are typos or wrong units,
// which would otherwise run and give wrong results.
constexpr double kMaxAbsHeight_m = 20000;  // DEM heights
constexpr double kMinDensity_kg_m3 = 100, kMaxDensity_kg_m3 = 30000;
constexpr double kMinVolume_m3 = 1e-9, kMaxVolume_m3 = 1e6;
constexpr double kMaxSpeed_m_s = 200, kMaxAngularSpeed_rad_s = 1000;
constexpr double kMaxReleaseHeight_m = 10000;
constexpr double kMinGravity_m_s2 = 0.1, kMaxGravity_m_s2 = 100;

// "<v> is outside <lo> .. <hi> <unit>", or "" when lo <= v <= hi.
std::string OutsideBounds(double v, double lo, double hi, const std::string& unit) {
  if (v >= lo && v <= hi) return "";
  return Fmt(v) + " is outside " + Fmt(lo) + " .. " + Fmt(hi) + " " + unit;
}

// Fails on `key` unless lo <= v <= hi.
void RequireWithin(const Section& s, const std::string& key, double v, double lo, double hi,
                   const std::string& unit) {
  if (const std::string why = OutsideBounds(v, lo, hi, unit); !why.empty()) s.Fail(key, why);
}

// "" when |v| <= max, else "|v| = <|v|> <unit> is more than <max> <unit>".
std::string TooFast(const Eigen::Vector3d& v, double max, const std::string& unit) {
  if (v.norm() <= max) return "";
  return "|v| = " + Fmt(v.norm()) + " " + unit + " is more than " + Fmt(max) + " " + unit;
}

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

// [terrain] ground_polygons = { file, field }: the polygons rasterised onto the DEM's grid (a
// node takes the category of the last polygon holding it), over the ground raster's category at
// the node where there is one.
void LoadGroundPolygons(const Context& context, const Section& terrain, SceneFile& out) {
  const toml::node* node = terrain.Node("ground_polygons");
  if (!node->is_table())
    terrain.Fail("ground_polygons", "expected an inline table { file = \"...\", field = \"...\" }");
  const Section s(context, node->as_table(), "terrain.ground_polygons", {"file", "field"});
  for (const char* required : {"file", "field"})
    if (!s.Has(required))
      context.Fail(node, s.Key(required), "missing: give the vector file and its category field");
  const std::string path = context.Resolve(s.String("file", ""));
  const std::string field = s.String("field", "");
  const std::string what = context.Where(node) + ": " + terrain.Key("ground_polygons");
  const std::vector<GroundPolygon> polygons = ReadGroundPolygons(path, out.crs_wkt, field, what);
  out.inputs.push_back(path);
  Scene& scene = out.scene;
  std::vector<std::vector<std::vector<Eigen::Vector2d>>> rings;
  std::vector<int> burn;
  for (const GroundPolygon& p : polygons) {
    int index = p.numeric ? -1 : scene.ground.IndexOfName(p.value);
    if (index < 0 && (p.numeric || p.value.find_first_not_of("0123456789") == std::string::npos)) {
      const long code = std::strtol(p.value.c_str(), nullptr, 10);
      if (code >= 0 && code <= 254) index = scene.ground.IndexOfCode(static_cast<int>(code));
    }
    if (index < 0) {
      std::vector<std::string> names;
      for (int k = 0; k < scene.ground.size(); ++k) names.push_back(scene.ground.category(k).name);
      const std::string hint = p.numeric ? "" : ClosestName(p.value, names);
      throw InputError(p.where + ": field '" + field + "' is '" + p.value +
                       "', which is neither the name nor the code of a ground category" +
                       (hint.empty() ? "" : " (did you mean '" + hint + "'?)"));
    }
    rings.push_back(p.rings);
    burn.push_back(index);
  }
  const GridGeometry& d = scene.terrain.heights().grid;
  const std::vector<int> burnt = RasterisePolygons(d, rings, burn);
  GroundGrid grid;
  grid.grid = d;
  grid.index.resize(burnt.size());
  bool any = false;
  const bool raster = scene.terrain.has_ground_grid();
  for (std::size_t k = 0; k < burnt.size(); ++k) {
    any = any || burnt[k] >= 0;
    if (burnt[k] >= 0) {
      grid.index[k] = static_cast<std::uint8_t>(burnt[k]);
    } else if (raster) {
      const double x = d.x0_m + d.dx_m * static_cast<double>(k % static_cast<std::size_t>(d.nx));
      const double y = d.y0_m + d.dy_m * static_cast<double>(k / static_cast<std::size_t>(d.nx));
      grid.index[k] = static_cast<std::uint8_t>(scene.terrain.GroundAt(x, y));
    } else {
      grid.index[k] = GroundGrid::kNoGround;
    }
  }
  if (!any)
    throw InputError(what + ": " + path + " covers no cell centre of the DEM (x " + Fmt(d.x0_m) +
                     " .. " + Fmt(d.x_max_m()) + ", y " + Fmt(d.y0_m) + " .. " + Fmt(d.y_max_m()) +
                     "): every contact would get the default ground");
  scene.terrain.SetGroundGrid(std::move(grid));
  std::string why;
  if (!scene.terrain.IsValid(&why)) terrain.Fail("ground_polygons", why);
}

void LoadTerrain(const Context& context, const Section& s, SceneFile& out) {
  Scene& scene = out.scene;
  if (s.Has("dem") == s.Has("plane"))
    s.Fail(s.Has("dem") ? "plane" : "dem", "give exactly one of 'dem' and 'plane'");
  Heightfield heights;
  if (s.Has("plane")) {
    const toml::node* node = s.Node("plane");
    if (!node->is_table()) s.Fail("plane", "expected an inline table { slope_deg = ..., ... }");
    const Section p(context, node->as_table(), "terrain.plane",
                    {"slope_deg", "slope_length_m", "runout_m", "width_m", "cell_m"});
    PlaneSpec spec;
    spec.slope_deg = p.Number("slope_deg", spec.slope_deg);
    spec.slope_length_m = p.Number("slope_length_m", spec.slope_length_m);
    spec.runout_m = p.Number("runout_m", spec.runout_m);
    spec.width_m = p.Number("width_m", spec.width_m);
    spec.cell_m = p.Number("cell_m", spec.cell_m);
    std::string why;
    if (!spec.IsValid(&why)) p.FailCheck(why);
    heights = MakePlaneHeightfield(spec);
    out.plane = spec;
    out.terrain_description =
        "plane " + Fmt(spec.slope_deg) + " deg, " + std::to_string(heights.grid.nx) + " x " +
        std::to_string(heights.grid.ny) + " cells of " + Fmt(spec.cell_m) + " m";
  } else {
    const std::string path = context.Resolve(s.String("dem", ""));
    Raster dem = ReadRaster(path, context.Where(s.Node("dem")) + ": " + s.Key("dem"));
    if (IsGeographicCrs(dem.crs_wkt)) {
      const std::string utm = UtmEpsgFor(0.5 * (dem.grid.x0_m + dem.grid.x_max_m()),
                                         0.5 * (dem.grid.y0_m + dem.grid.y_max_m()));
      s.Fail("dem", path +
                        " is in a geographic CRS (degrees); Talus needs a projected CRS in metres: "
                        "reproject it (e.g. gdalwarp -t_srs " +
                        (utm.empty() ? "EPSG:<a projected CRS in metres>"
                                     : utm + ", the UTM zone of its centre") +
                        ")");
    }
    for (std::size_t k = 0; k < dem.values.size(); ++k)
      if (std::abs(dem.values[k]) > kMaxAbsHeight_m)  // false for nodata (NaN)
        s.Fail("dem", path + " has the height " + Fmt(dem.values[k]) + " m (cell " +
                          std::to_string(k % static_cast<std::size_t>(dem.grid.nx)) + ", " +
                          std::to_string(k / static_cast<std::size_t>(dem.grid.nx)) +
                          " from the south-west), beyond +-" + Fmt(kMaxAbsHeight_m) +
                          " m: a nodata value the file does not declare, or not metres?");
    out.inputs.push_back(path);
    out.crs_wkt = dem.crs_wkt;
    heights.grid = dem.grid;
    heights.z_m = std::move(dem.values);
    out.terrain_description =
        fs::path(path).filename().string() + " (" + std::to_string(heights.grid.nx) + " x " +
        std::to_string(heights.grid.ny) + " cells of " + Fmt(heights.grid.dx_m) + " m)";
  }
  const std::string default_name = s.String("default_ground", "medium");
  const int default_index = scene.ground.IndexOfName(default_name);
  if (default_index < 0) {
    std::vector<std::string> names;
    for (int k = 0; k < scene.ground.size(); ++k) names.push_back(scene.ground.category(k).name);
    const std::string hint = ClosestName(default_name, names);
    s.Fail("default_ground", "unknown ground category '" + default_name + "'" +
                                 (hint.empty() ? "" : " (did you mean '" + hint + "'?)"));
  }
  scene.terrain = Terrain(std::move(heights), default_index);
  std::string why;
  if (!scene.terrain.IsValid(&why)) s.Fail(s.Has("dem") ? "dem" : "plane", why);

  if (s.Has("ground")) {
    const std::string path = context.Resolve(s.String("ground", ""));
    const std::string what = context.Where(s.Node("ground")) + ": " + s.Key("ground");
    std::string reprojected_from;
    const Raster codes = ReadRasterIn(path, out.crs_wkt, what, &reprojected_from);
    out.inputs.push_back(path);
    if (!reprojected_from.empty())
      out.terrain_description += ", ground map reprojected from " + DescribeCrs(reprojected_from);
    // A ground raster off the DEM would give the default ground everywhere.
    const GridGeometry& d = scene.terrain.heights().grid;
    const GridGeometry& c = codes.grid;
    const double cx0 = c.x0_m - 0.5 * c.dx_m, cx1 = c.x_max_m() + 0.5 * c.dx_m;
    const double cy0 = c.y0_m - 0.5 * c.dy_m, cy1 = c.y_max_m() + 0.5 * c.dy_m;
    if (!(cx0 < d.x_max_m() && cx1 > d.x0_m && cy0 < d.y_max_m() && cy1 > d.y0_m))
      s.Fail("ground", path + " covers x " + Fmt(cx0) + " .. " + Fmt(cx1) + ", y " + Fmt(cy0) +
                           " .. " + Fmt(cy1) + ", which does not overlap the DEM (x " +
                           Fmt(d.x0_m) + " .. " + Fmt(d.x_max_m()) + ", y " + Fmt(d.y0_m) + " .. " +
                           Fmt(d.y_max_m()) + "): every contact would get the default ground");
    GroundGrid grid;
    grid.grid = codes.grid;
    grid.index.resize(codes.values.size());
    for (std::size_t k = 0; k < codes.values.size(); ++k) {
      const double v = codes.values[k];
      if (std::isnan(v)) {
        grid.index[k] = GroundGrid::kNoGround;
        continue;
      }
      const bool code = v == std::round(v) && v >= 0 && v <= 254;  // and so fits an int
      const int index = code ? scene.ground.IndexOfCode(static_cast<int>(v)) : -1;
      if (index < 0)
        throw InputError(what + ": " + path + " has the value " + Fmt(v) + " (cell " +
                         std::to_string(k % static_cast<std::size_t>(codes.grid.nx)) + ", " +
                         std::to_string(k / static_cast<std::size_t>(codes.grid.nx)) +
                         " from the south-west), which is not the code of any ground category");
      grid.index[k] = static_cast<std::uint8_t>(index);
    }
    scene.terrain.SetGroundGrid(std::move(grid));
    if (!scene.terrain.IsValid(&why)) s.Fail("ground", why);
  }
  if (s.Has("ground_polygons")) LoadGroundPolygons(context, s, out);
}

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
    const Section b(context, shape->as_table(), "rock.shape",
                    {"box", "ellipsoid", "sphere", "cylinder", "rock", "eota", "size_m", "points",
                     "roughness", "shape_seed"});
    int kinds = 0;
    for (const char* kind : {"box", "ellipsoid", "sphere", "cylinder", "rock", "eota"})
      kinds += b.Has(kind);
    if (kinds != 1)
      s.Fail(
          "shape",
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
      if (b.Has(knob) && !b.Has("rock"))
        b.Fail(knob, "only a rock shape takes " + std::string(knob));
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

std::vector<Eigen::Vector2d> PointList(const Section& s, const toml::node* node,
                                       const std::string& key) {
  const toml::array* array = node ? node->as_array() : nullptr;
  if (!array) s.context().Fail(node, key, "expected a list of [x, y] points");
  std::vector<Eigen::Vector2d> out;
  for (std::size_t k = 0; k < array->size(); ++k) {
    const std::vector<double> xy =
        s.NumbersOf(array->get(k), key + "[" + std::to_string(k) + "]", 2);
    out.emplace_back(xy[0], xy[1]);
  }
  return out;
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

// [blocks]: named rocks that runs refer to, from a table file (block_id, mass_kg, size_x_m,
// size_y_m, size_z_m, optional shape) and/or [blocks.<id>] tables (mass_kg, size_m = [x, y, z],
// optional shape), each a built-in shape built from its size: `shape` of the block, else that of
// [blocks]. EOTA blocks keep the size as their bounding box and take the bevel for the volume
// mass_kg / density_kg_m3 (without a mass: the standard bevel-to-side ratio).
void LoadBlocks(const Context& context, const toml::table* table, SceneFile& out) {
  if (!table) return;
  const std::vector<std::string> reserved = {"file",      "shape",         "points",
                                             "roughness", "density_kg_m3", "shape_per_rock"};
  std::vector<std::string> known = reserved;
  for (const auto& [key, node] : *table)
    if (node.is_table()) known.emplace_back(key.str());
  const Section s(context, table, "blocks", known);
  const std::vector<std::string> shapes = {"box", "ellipsoid", "rock", "eota111", "eota221"};
  const std::string kShapes =
      "expected \"box\", \"ellipsoid\", \"rock\", \"eota111\" or \"eota221\"";
  const auto known_shape = [&](const std::string& name) {
    return std::find(shapes.begin(), shapes.end(), name) != shapes.end();
  };
  const std::string shape = s.String("shape", "box");
  if (!known_shape(shape)) s.Fail("shape", "'" + shape + "': " + kShapes);
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
  out.shape_per_rock = s.Bool("shape_per_rock", false);

  auto add = [&](const std::string& id, const std::string& block_shape, std::optional<double> mass,
                 const std::vector<double>& size, const std::string& where) {
    for (const ensemble::Block& b : out.release.blocks)
      if (b.id == id) throw InputError(where + ": block '" + id + "' is defined twice");
    pointclouds::RockSpec spec = base;
    spec.builtin = block_shape;
    spec.dimensions_m = size;
    spec.mass_kg = mass;
    spec.density_kg_m3 = base.density_kg_m3;
    out.block_specs.push_back(spec);
    auto block_shape_made = MakeBlockShape(spec, where);
    if (const std::string bad =
            OutsideBounds(block_shape_made->volume_m3, kMinVolume_m3, kMaxVolume_m3, "m3");
        !bad.empty())
      throw InputError(where + ": block '" + id + "': the volume " + bad);
    out.release.blocks.push_back({id, std::move(block_shape_made)});
  };
  if (s.Has("file")) {
    const std::string path = context.Resolve(s.String("file", ""));
    if (!fs::exists(path)) s.Fail("file", "file not found: " + path);
    out.inputs.push_back(path);
    const CsvTable rows = CsvTable::Read(path);
    rows.Require({"block_id", "size_x_m", "size_y_m", "size_z_m"});
    for (int k = 0; k < rows.rows(); ++k) {
      std::vector<double> size;
      for (const char* c : {"size_x_m", "size_y_m", "size_z_m"}) {
        size.push_back(rows.Number(k, c));
        if (size.back() <= 0) throw InputError(rows.Where(k, c) + ": must be > 0");
      }
      const std::optional<double> mass = rows.OptionalNumber(k, "mass_kg");
      if (mass && *mass <= 0) throw InputError(rows.Where(k, "mass_kg") + ": must be > 0");
      const std::string id = rows.Text(k, "block_id");
      if (id.empty()) throw InputError(rows.Where(k, "block_id") + ": empty");
      const std::string block_shape = rows.Empty(k, "shape") ? shape : rows.Text(k, "shape");
      if (!known_shape(block_shape))
        throw InputError(rows.Where(k, "shape") + ": '" + block_shape + "': " + kShapes);
      add(id, block_shape, mass, size, rows.Where(k, "block_id"));
    }
  }
  for (const auto& [key, node] : *table) {
    if (!node.is_table()) continue;
    const std::string id(key.str());
    const Section b(context, node.as_table(), "blocks." + id, {"mass_kg", "size_m", "shape"});
    if (!b.Has("size_m")) b.Fail("size_m", "missing: the block's size [x, y, z] in m");
    const std::vector<double> size = b.Numbers("size_m", 3);
    for (double v : size)
      if (v <= 0) b.Fail("size_m", "dimensions must be > 0");
    std::optional<double> mass;
    if (b.Has("mass_kg")) mass = b.Checked("mass_kg", 0, kPositive, "must be > 0");
    const std::string block_shape = b.String("shape", shape);
    if (!known_shape(block_shape)) b.Fail("shape", "'" + block_shape + "': " + kShapes);
    add(id, block_shape, mass, size, context.Where(&node) + ": blocks." + id);
  }
  if (out.release.blocks.empty())
    context.Fail(table, "blocks", "no block: give a file or [blocks.<id>] tables");
  // Knobs of the random rock shape need rock blocks.
  const bool all_rocks =
      std::all_of(out.block_specs.begin(), out.block_specs.end(),
                  [](const pointclouds::RockSpec& b) { return b.builtin == "rock"; });
  const bool any_rock =
      std::any_of(out.block_specs.begin(), out.block_specs.end(),
                  [](const pointclouds::RockSpec& b) { return b.builtin == "rock"; });
  if ((s.Has("points") || s.Has("roughness")) && !any_rock)
    s.Fail(s.Has("points") ? "points" : "roughness", "only rock blocks take points and roughness");
  if (out.shape_per_rock && !all_rocks)
    s.Fail("shape_per_rock", "only rock blocks have a shape of their own per rock");
}

// The block a row of a run table names in its column `block_column` (the index into [blocks]), or
// -1 for the scene's [rock] when the cell is empty.
int BlockOfRow(const CsvTable& rows, int k, const std::string& block_column, const SceneFile& out) {
  const ensemble::ReleaseSpec& r = out.release;
  if (rows.Empty(k, block_column)) {
    if (!out.has_rock)
      throw InputError(rows.Where(k, block_column) +
                       ": a run without a block needs the scene's [rock]");
    return -1;
  }
  const std::string id = rows.Text(k, block_column);
  std::string known;
  for (std::size_t b = 0; b < r.blocks.size(); ++b) {
    if (r.blocks[b].id == id) return static_cast<int>(b);
    known += (known.empty() ? "" : ", ") + r.blocks[b].id;
  }
  throw InputError(rows.Where(k, block_column) + ": unknown block '" + id + "'" +
                   (r.blocks.empty() ? " (the scene has no [blocks])" : " (known: " + known + ")"));
}

// [release] runs = "file.csv": one row per run, columns by name (docs/scenes.md). A run names its
// block by the text of the column `block_column` (default block_id; e.g. mass_kg when the blocks
// are told apart by their mass).
void LoadRuns(const Context& context, const Section& s, SceneFile& out) {
  ensemble::ReleaseSpec& r = out.release;
  const std::string path = context.Resolve(s.String("runs", ""));
  if (!fs::exists(path)) s.Fail("runs", "file not found: " + path);
  const std::string block_column = s.String("block_column", "block_id");
  if (block_column.empty()) s.Fail("block_column", "empty: name a column of the run table");
  out.inputs.push_back(path);
  const CsvTable rows = CsvTable::Read(path);
  rows.Require({"trajectory_id", "x_m", "y_m"});
  if (s.Has("block_column")) {
    try {
      rows.Require({block_column});
    } catch (const InputError& e) {
      s.Fail("block_column", e.what());
    }
  }
  if (rows.rows() == 0) throw InputError(path + ": no run (the table has a header only)");
  const GridGeometry& g = out.scene.terrain.heights().grid;
  for (int k = 0; k < rows.rows(); ++k) {
    ensemble::ReleaseRun run;
    run.id = rows.Text(k, "trajectory_id");
    if (run.id.empty()) throw InputError(rows.Where(k, "trajectory_id") + ": empty");
    for (const ensemble::ReleaseRun& other : r.runs)
      if (other.id == run.id)
        throw InputError(rows.Where(k, "trajectory_id") + ": run '" + run.id + "' appears twice");
    run.xy_m = Eigen::Vector2d(rows.Number(k, "x_m"), rows.Number(k, "y_m"));
    run.z_m = rows.OptionalNumber(k, "z_m");
    run.height_m = rows.OptionalNumber(k, "height_m");
    if (run.height_m && *run.height_m < 0)
      throw InputError(rows.Where(k, "height_m") + ": must be >= 0");
    if (run.height_m && *run.height_m > kMaxReleaseHeight_m)
      throw InputError(rows.Where(k, "height_m") + ": " + Fmt(*run.height_m) + " is more than " +
                       Fmt(kMaxReleaseHeight_m) + " m");
    const auto vector = [&](const char* x, const char* y, const char* z) {
      return Eigen::Vector3d(rows.OptionalNumber(k, x).value_or(0),
                             rows.OptionalNumber(k, y).value_or(0),
                             rows.OptionalNumber(k, z).value_or(0));
    };
    run.velocity_m_s = vector("vx_mps", "vy_mps", "vz_mps");
    run.angular_velocity_rad_s = vector("wx_radps", "wy_radps", "wz_radps");
    // Errors name the column of the largest component.
    const auto largest = [](const Eigen::Vector3d& v, const char* x, const char* y, const char* z) {
      Eigen::Index at = 0;
      v.cwiseAbs().maxCoeff(&at);
      return at == 0 ? x : at == 1 ? y : z;
    };
    if (const std::string bad = TooFast(run.velocity_m_s, kMaxSpeed_m_s, "m/s"); !bad.empty())
      throw InputError(rows.Where(k, largest(run.velocity_m_s, "vx_mps", "vy_mps", "vz_mps")) +
                       ": start velocity " + bad);
    if (const std::string bad =
            TooFast(run.angular_velocity_rad_s, kMaxAngularSpeed_rad_s, "rad/s");
        !bad.empty())
      throw InputError(
          rows.Where(k, largest(run.angular_velocity_rad_s, "wx_radps", "wy_radps", "wz_radps")) +
          ": start angular velocity " + bad);
    if (rows.Has("qw") && !rows.Empty(k, "qw")) {
      const Eigen::Quaterniond q(rows.Number(k, "qw"), rows.Number(k, "qx"), rows.Number(k, "qy"),
                                 rows.Number(k, "qz"));
      if (std::abs(q.norm() - 1) > 1e-3)
        throw InputError(rows.Where(k, "qw") + ": quaternion [qw, qx, qy, qz] has norm " +
                         Fmt(q.norm()) + ", expected 1");
      run.orientation = q.normalized();
    }
    run.block = BlockOfRow(rows, k, block_column, out);
    double ground_m;
    if (!out.scene.terrain.Height(run.xy_m.x(), run.xy_m.y(), &ground_m))
      throw InputError(rows.Where(k, "x_m") + ": (" + Fmt(run.xy_m.x()) + ", " + Fmt(run.xy_m.y()) +
                       ") is outside the DEM or on nodata (the DEM covers x " + Fmt(g.x0_m) +
                       " .. " + Fmt(g.x_max_m()) + ", y " + Fmt(g.y0_m) + " .. " +
                       Fmt(g.y_max_m()) + ")");
    if (run.z_m && *run.z_m - ground_m > kMaxReleaseHeight_m)
      throw InputError(rows.Where(k, "z_m") + ": " + Fmt(*run.z_m) + " m is " +
                       Fmt(*run.z_m - ground_m) + " m above the ground, more than " +
                       Fmt(kMaxReleaseHeight_m) + " m");
    r.runs.push_back(run);
  }
}

// [release] single_impacts = { file = "impacts.csv", ... }: one run per impact of the table
// (fieldobs/single_impacts.hpp, docs/scenes.md), each starting at `at` (default: the middle of a
// plane's slope) with the lowest vertex clearance_m above the ground, with the incoming velocity
// relative to the terrain's tangent plane there. Blocks by `block_column` as for run tables.
void LoadSingleImpacts(const Context& context, const Section& release, SceneFile& out) {
  const toml::node* node = release.Node("single_impacts");
  if (!node->is_table())
    release.Fail("single_impacts", "expected an inline table { file = \"impacts.csv\", ... }");
  const Section s(
      context, node->as_table(), release.Key("single_impacts"),
      {"file", "at", "clearance_m", "id_column", "normal_speed_column", "tangent_speed_column",
       "total_speed_column", "angle_column", "angular_speed_column"});
  if (!s.Has("file")) context.Fail(node, s.Key("file"), "missing");
  for (const char* key : {"height_m", "height_reference", "velocity_m_s", "angular_velocity_rad_s"})
    if (release.Has(key))
      release.Fail(key, "a single-impact table sets each run's start (single_impacts)");
  const std::string path = context.Resolve(s.String("file", ""));
  if (!fs::exists(path)) s.Fail("file", "file not found: " + path);
  fieldobs::SingleImpactColumns columns;
  columns.id = s.String("id_column", columns.id);
  columns.normal_speed = s.String("normal_speed_column", columns.normal_speed);
  columns.tangent_speed = s.String("tangent_speed_column", columns.tangent_speed);
  columns.total_speed = s.String("total_speed_column", columns.total_speed);
  columns.angle = s.String("angle_column", columns.angle);
  columns.angular_speed = s.String("angular_speed_column", "");
  const double clearance_m = s.Checked(
      "clearance_m", 0.001, [](double v) { return v >= 0 && v <= 1; }, "must be in 0 .. 1 m");
  Eigen::Vector2d at;
  if (s.Has("at")) {
    const std::vector<double> xy = s.Numbers("at", 2);
    at = Eigen::Vector2d(xy[0], xy[1]);
  } else if (out.plane) {  // the middle of the slope, or of the runout of a level plane
    const PlaneSpec& p = *out.plane;
    at = Eigen::Vector2d(0.5 * (p.slope_length_m > 0 ? p.slope_length_m : p.runout_m), 0);
  } else {
    s.Fail("at", "missing: give the point [x, y] of the DEM where the impacts happen");
  }
  if (!ensemble::OnTerrain(out.scene.terrain, at))
    s.Fail("at", "(" + Fmt(at.x()) + ", " + Fmt(at.y()) + ") is outside the DEM or on nodata");
  const std::string block_column = release.String("block_column", "block_id");
  out.inputs.push_back(path);
  const CsvTable rows = CsvTable::Read(path);
  if (release.Has("block_column")) {
    try {
      rows.Require({block_column});
    } catch (const InputError& e) {
      release.Fail("block_column", e.what());
    }
  }
  const std::vector<fieldobs::IncomingImpact> impacts =
      fieldobs::ReadIncomingImpacts(rows, columns);
  for (int k = 0; k < rows.rows(); ++k) {
    const fieldobs::IncomingImpact& impact = impacts[static_cast<std::size_t>(k)];
    const double speed = std::hypot(impact.normal_speed_m_s, impact.tangent_speed_m_s);
    if (speed > kMaxSpeed_m_s)
      throw InputError(impact.where + ": incoming speed " + Fmt(speed) + " m/s is more than " +
                       Fmt(kMaxSpeed_m_s) + " m/s");
    if (std::abs(impact.angular_speed_rad_s) > kMaxAngularSpeed_rad_s)
      throw InputError(rows.Where(k, columns.angular_speed) + ": more than " +
                       Fmt(kMaxAngularSpeed_rad_s) + " rad/s");
    out.release.runs.push_back(fieldobs::SingleImpactRun(impact, out.scene.terrain, at, clearance_m,
                                                         BlockOfRow(rows, k, block_column, out)));
  }
  out.release.height_reference = ensemble::ReleaseSpec::HeightReference::kLowestPoint;
}

void LoadRelease(const Context& context, const Section& s, SceneFile& out) {
  ensemble::ReleaseSpec& r = out.release;
  // Where each release came from, for errors: "<file>:<line>: <key>[k]".
  std::vector<std::string> origin;
  if (s.Has("points")) {
    const auto points = PointList(s, s.Node("points"), s.Key("points"));
    for (std::size_t k = 0; k < points.size(); ++k) {
      r.releases.push_back({ReleaseGeometry::Kind::kPoint, {{points[k]}}});
      origin.push_back(context.Where(s.Node("points")->as_array()->get(k)) + ": " +
                       s.Key("points") + "[" + std::to_string(k) + "]");
    }
  }
  for (const auto& [key, kind] :
       {std::pair{std::string("lines"), ReleaseGeometry::Kind::kLine},
        std::pair{std::string("polygons"), ReleaseGeometry::Kind::kPolygon}}) {
    if (!s.Has(key)) continue;
    const toml::array* array = s.Node(key)->as_array();
    if (!array) s.Fail(key, "expected a list of " + key + ", each a list of [x, y] points");
    for (std::size_t k = 0; k < array->size(); ++k) {
      const std::string name = s.Key(key) + "[" + std::to_string(k) + "]";
      r.releases.push_back({kind, {PointList(s, array->get(k), name)}});
      origin.push_back(context.Where(array->get(k)) + ": " + name);
    }
  }
  if (s.Has("file")) {
    const std::string path = context.Resolve(s.String("file", ""));
    FeatureSelection select;
    if (s.Has("layer")) {
      select.layer = s.String("layer", "");
      select.layer_what = context.Where(s.Node("layer")) + ": " + s.Key("layer");
    }
    if (s.Has("where")) {
      select.where = s.String("where", "");
      select.where_what = context.Where(s.Node("where")) + ": " + s.Key("where");
    }
    const auto geometries = ReadReleaseGeometries(
        path, out.crs_wkt, context.Where(s.Node("file")) + ": " + s.Key("file"), select);
    out.inputs.push_back(path);
    for (std::size_t k = 0; k < geometries.size(); ++k) {
      r.releases.push_back(geometries[k]);
      origin.push_back(context.Where(s.Node("file")) + ": " + s.Key("file") + " (" + path +
                       ", geometry " + std::to_string(k) + ")");
    }
  }
  for (const char* key : {"layer", "where"})
    if (s.Has(key) && !s.Has("file"))
      s.Fail(key, "chooses features of a vector file: give file = \"...\" as well");
  if (s.Has("runs")) {
    if (!r.releases.empty())
      s.Fail("runs", "a run table cannot be combined with points, lines, polygons or a file");
    for (const char* key : {"velocity_m_s", "angular_velocity_rad_s"})
      if (s.Has(key))
        s.Fail(key, "a run table gives each run's start velocities (columns vx_mps .. wz_radps)");
    LoadRuns(context, s, out);
  }
  if (s.Has("single_impacts")) {
    if (!r.releases.empty() || s.Has("runs"))
      s.Fail(
          "single_impacts",
          "a single-impact table cannot be combined with points, lines, polygons, a file or runs");
    LoadSingleImpacts(context, s, out);
  }
  if (r.releases.empty() && r.runs.empty())
    s.Fail("points",
           "missing: give points, lines, polygons, a vector file, a run table (runs) or a "
           "single-impact table (single_impacts)");

  const std::vector<std::string> count_keys = {"rocks", "rocks_per_m2", "rocks_per_cell"};
  std::string count_key = "rocks";
  for (const std::string& key : count_keys)
    if (s.Has(key)) {
      if (key != count_key && s.Has(count_key))
        s.Fail(key,
               "give one of rocks, rocks_per_m2 and rocks_per_cell, not " + count_key + " as well");
      count_key = key;
    }
  const long rocks = s.Integer("rocks", 1);
  if (rocks < 1) s.Fail("rocks", std::to_string(rocks) + " must be >= 1");
  r.rocks_per_release = rocks;
  r.height_m = s.Checked(
      "height_m", 1.0, [](double v) { return v >= 0; }, "must be >= 0");
  if (r.height_m > kMaxReleaseHeight_m)
    s.Fail("height_m", Fmt(r.height_m) + " is more than " + Fmt(kMaxReleaseHeight_m) + " m");
  if (s.Has("height_reference")) {
    const std::string name = s.String("height_reference", "");
    if (name == "lowest_point") {
      r.height_reference = ensemble::ReleaseSpec::HeightReference::kLowestPoint;
    } else if (name != "centre_of_mass") {
      const std::string hint = ClosestName(name, {"centre_of_mass", "lowest_point"});
      s.Fail("height_reference", "unknown reference '" + name + "'" +
                                     (hint.empty() ? "" : " (did you mean '" + hint + "'?)") +
                                     "; known: centre_of_mass, lowest_point");
    }
  }
  r.clip_to_dem = s.Bool("clip_to_dem", false);
  if (const toml::node* node = s.Node("orientation")) {
    if (node->is_string()) {
      if (s.String("orientation", "") != "random")
        s.Fail("orientation", "expected \"random\" or a unit quaternion [w, x, y, z]");
    } else {
      const std::vector<double> q = s.Numbers("orientation", 4);
      const Eigen::Quaterniond quat(q[0], q[1], q[2], q[3]);
      if (std::abs(quat.norm() - 1) > 1e-3)
        s.Fail("orientation",
               "quaternion [w, x, y, z] has norm " + Fmt(quat.norm()) + ", expected 1");
      r.orientation = quat.normalized();
    }
  }
  if (s.Has("velocity_m_s")) {
    const auto v = s.Numbers("velocity_m_s", 3);
    r.velocity_m_s = Eigen::Vector3d(v[0], v[1], v[2]);
    if (const std::string bad = TooFast(r.velocity_m_s, kMaxSpeed_m_s, "m/s"); !bad.empty())
      s.Fail("velocity_m_s", bad);
  }
  if (s.Has("angular_velocity_rad_s")) {
    const auto w = s.Numbers("angular_velocity_rad_s", 3);
    r.angular_velocity_rad_s = Eigen::Vector3d(w[0], w[1], w[2]);
    if (const std::string bad = TooFast(r.angular_velocity_rad_s, kMaxAngularSpeed_rad_s, "rad/s");
        !bad.empty())
      s.Fail("angular_velocity_rad_s", bad);
  }
  const long seed = s.Integer("seed", 1);
  if (seed < 0) s.Fail("seed", std::to_string(seed) + " must be >= 0");
  r.seed = static_cast<std::uint64_t>(seed);

  for (std::size_t k = 0; k < r.releases.size(); ++k)
    if (const std::string problem = ensemble::ReleaseGeometryProblem(r.releases[k]);
        !problem.empty())
      throw InputError(origin[k] + ": " + problem);
  // Every point a rock can start from must lie on valid terrain: vertices, lines, polygon insides;
  // with clip_to_dem, lines and polygons start rocks only where it has a height (but somewhere).
  const GridGeometry& g = out.scene.terrain.heights().grid;
  std::vector<double> on_terrain(r.releases.size(), 1.0);  // fraction of each release
  for (std::size_t k = 0; k < r.releases.size(); ++k) {
    const ReleaseGeometry& release = r.releases[k];
    const auto v = ensemble::PointOffTerrain(out.scene.terrain, release);
    if (!v) continue;
    const std::string dem = " (the DEM covers x " + Fmt(g.x0_m) + " .. " + Fmt(g.x_max_m()) +
                            ", y " + Fmt(g.y0_m) + " .. " + Fmt(g.y_max_m()) + ")";
    if (!r.clip_to_dem || release.kind == ReleaseGeometry::Kind::kPoint)
      throw InputError(origin[k] + ": (" + Fmt(v->x()) + ", " + Fmt(v->y()) +
                       ") is outside the DEM or on nodata" + dem +
                       (r.clip_to_dem ? "" : "; clip_to_dem = true starts rocks on the rest"));
    on_terrain[k] = ensemble::FractionOnTerrain(out.scene.terrain, release);
    if (on_terrain[k] == 0)
      throw InputError(origin[k] + ": lies entirely outside the DEM or on nodata" + dem +
                       ": clip_to_dem leaves no start point");
    // Start points are drawn by rejection: the part on the terrain must not be a sliver.
    double fill = on_terrain[k];
    if (release.kind == ReleaseGeometry::Kind::kPolygon) {
      Eigen::Vector2d lo = release.rings[0][0], hi = lo;
      for (const Eigen::Vector2d& p : release.rings[0]) {
        lo = lo.cwiseMin(p);
        hi = hi.cwiseMax(p);
      }
      fill *= ensemble::ReleaseArea(release) / (hi - lo).prod();
    }
    if (fill < ensemble::kMinPolygonFill)
      throw InputError(origin[k] + ": the part on valid DEM cells is " + Fmt(100 * fill) +
                       " % of its " +
                       (release.kind == ReleaseGeometry::Kind::kLine ? "length" : "bounding box") +
                       ", less than " + Fmt(100 * ensemble::kMinPolygonFill) +
                       " %: too little to draw start points from" + dem);
  }
  if (count_key != "rocks") {
    // Rocks by area: round(density x area on the terrain) per polygon, at least 1.
    const bool per_cell = count_key == "rocks_per_cell";
    const double density = s.Checked(
        count_key, 1.0, [](double v) { return v > 0; }, "must be > 0");
    const double per_m2 = per_cell ? density / (g.dx_m * g.dy_m) : density;
    if (!r.runs.empty())
      s.Fail(count_key, "rocks by area are for polygons, not the runs of a run table");
    std::vector<long> counts;
    for (std::size_t k = 0; k < r.releases.size(); ++k) {
      if (r.releases[k].kind != ReleaseGeometry::Kind::kPolygon)
        s.Fail(count_key,
               "rocks by area are for polygons only, but " + origin[k] + " is a " +
                   (r.releases[k].kind == ReleaseGeometry::Kind::kPoint ? "point" : "line") +
                   ": give rocks instead");
      const double n = std::round(per_m2 * ensemble::ReleaseArea(r.releases[k]) * on_terrain[k]);
      if (!(n <= double(ensemble::ReleaseSpec::kMaxTotalRocks)))
        s.Fail(count_key, Fmt(n) + " rocks for " + origin[k] + ", more than " +
                              std::to_string(ensemble::ReleaseSpec::kMaxTotalRocks));
      counts.push_back(std::max(1L, static_cast<long>(n)));
    }
    r.SetRocksPerRelease(counts);
  }
  std::string why;
  if (!r.IsValid(&why)) s.FailCheck(why);
}

// [evaluation_lines]: polylines where the rocks that cross are recorded (docs/scenes.md), from
// `lines` (named by `names`) and/or the line features of a vector file (named by `name_field`).
void LoadEvaluationLines(const Context& context, const Section& s, SceneFile& out) {
  if (!s.table()) return;
  std::vector<ensemble::EvaluationLine>& lines = out.evaluation_lines;
  std::vector<std::string> origin;  // "<file>:<line>: <key>[k]" of each line, for errors
  if (s.Has("lines")) {
    const toml::array* array = s.Node("lines")->as_array();
    if (!array) s.Fail("lines", "expected a list of lines, each a list of [x, y] points");
    for (std::size_t k = 0; k < array->size(); ++k) {
      const std::string name = s.Key("lines") + "[" + std::to_string(k) + "]";
      lines.push_back({"", PointList(s, array->get(k), name)});
      origin.push_back(context.Where(array->get(k)) + ": " + name);
    }
  }
  if (s.Has("names")) {
    if (!s.Has("lines"))
      s.Fail("names",
             "names are for the lines of 'lines'; the lines of a file are named by its "
             "name_field attribute");
    const toml::array* array = s.Node("names")->as_array();
    if (!array || array->size() != lines.size())
      s.Fail("names", "expected a list of " + std::to_string(lines.size()) +
                          " names, one per line of 'lines'");
    for (std::size_t k = 0; k < array->size(); ++k) {
      const auto name = array->get(k)->value<std::string>();
      if (!name || !array->get(k)->is_string())
        s.Fail("names", "expected a list of names (strings)");
      if (name->empty()) s.Fail("names", "names[" + std::to_string(k) + "] is empty");
      lines[k].name = *name;
    }
  }
  if (s.Has("name_field") && !s.Has("file"))
    s.Fail("name_field", "only the lines of a vector file ('file') are named by a name_field");
  if (s.Has("file")) {
    const std::string path = context.Resolve(s.String("file", ""));
    std::vector<std::string> where;
    std::vector<ensemble::EvaluationLine> from_file =
        ReadLineFeatures(path, out.crs_wkt, s.String("name_field", "name"), s.Has("name_field"),
                         context.Where(s.Node("file")) + ": " + s.Key("file"), &where);
    out.inputs.push_back(path);
    lines.insert(lines.end(), from_file.begin(), from_file.end());
    origin.insert(origin.end(), where.begin(), where.end());
  }
  if (lines.empty()) s.Fail("lines", "missing: give lines and/or a vector file of lines (file)");

  const GridGeometry& g = out.scene.terrain.heights().grid;
  const double spacing_m = 0.5 * std::min(g.dx_m, g.dy_m);
  for (std::size_t k = 0; k < lines.size(); ++k) {
    ensemble::EvaluationLine& line = lines[k];
    if (line.name.empty()) line.name = "line" + std::to_string(k + 1);
    if (line.vertices_m.size() < 2)
      throw InputError(origin[k] + ": a line needs at least 2 vertices, it has " +
                       std::to_string(line.vertices_m.size()));
    for (const Eigen::Vector2d& v : line.vertices_m)
      if (!v.allFinite()) throw InputError(origin[k] + ": a vertex is not finite");
    if (!(line.length_m() > 0))
      throw InputError(origin[k] + ": the line has zero length (all its vertices are one point)");
    // A line no rock can reach would report a passing probability of 0, which reads as "safe":
    // it is an error (almost always swapped coordinates or another CRS), not a warning.
    bool on_dem = false;
    for (std::size_t v = 1; v < line.vertices_m.size() && !on_dem; ++v) {
      const Eigen::Vector2d p = line.vertices_m[v - 1], q = line.vertices_m[v];
      const double n = std::min(1e6, std::ceil((q - p).norm() / spacing_m));
      for (double i = 0; i <= n && !on_dem; ++i) {
        const Eigen::Vector2d x = p + (n > 0 ? i / n : 0.0) * (q - p);
        double z = 0;
        on_dem = out.scene.terrain.Height(x.x(), x.y(), &z);
      }
    }
    if (!on_dem)
      throw InputError(origin[k] + ": the line '" + line.name +
                       "' lies entirely outside the DEM or on nodata (the DEM covers x " +
                       Fmt(g.x0_m) + " .. " + Fmt(g.x_max_m()) + ", y " + Fmt(g.y0_m) + " .. " +
                       Fmt(g.y_max_m()) + "), so no rock can cross it");
    for (std::size_t j = 0; j < k; ++j)
      if (lines[j].name == line.name)
        throw InputError(origin[k] + ": the name '" + line.name + "' is also that of " + origin[j] +
                         "; names must be unique");
  }
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
  o.tangential_restitution = s.Number("tangential_restitution", o.tangential_restitution);
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
  for (const std::string& key : scene.solver_keys_given) {
    if (key == "dt_s") o.dt_s = given.dt_s;
    if (key == "tolerance_m_s") o.tolerance_m_s = given.tolerance_m_s;
    if (key == "max_iterations") o.max_iterations = given.max_iterations;
  }
  scene.scene.options = o;
  scene.solver_preset = preset;
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
  LoadTerrain(context,
              Section(context, SubTable(context, root, "terrain"), "terrain",
                      {"dem", "plane", "ground", "ground_polygons", "default_ground"}),
              out);
  LoadBlocks(context, SubTable(context, root, "blocks"), out);
  out.has_rock = root.get("rock") != nullptr;
  if (out.has_rock) {
    LoadRock(context,
             Section(context, SubTable(context, root, "rock"), "rock",
                     {"shape", "density_kg_m3", "volume_m3", "mass_kg", "max_vertices",
                      "shape_per_rock", "clean"}),
             out);
  } else {
    out.scene.rock = *out.release.blocks.front().shape;  // the shape of runs' first block
    out.rock_description = "blocks (" + std::to_string(out.release.blocks.size()) + ")";
  }
  LoadRelease(context,
              Section(context, SubTable(context, root, "release"), "release",
                      {"points", "lines", "polygons", "file", "layer", "where", "runs",
                       "single_impacts", "block_column", "height_m", "height_reference", "rocks",
                       "rocks_per_m2", "rocks_per_cell", "clip_to_dem", "orientation",
                       "velocity_m_s", "angular_velocity_rad_s", "seed"}),
              out);
  LoadEvaluationLines(context,
                      Section(context, SubTable(context, root, "evaluation_lines"),
                              "evaluation_lines", {"lines", "names", "file", "name_field"}),
                      out);
  LoadSolver(Section(context, SubTable(context, root, "solver"), "solver",
                     {"preset", "dt_s", "max_time_s", "gravity_m_s2", "normal_restitution",
                      "tangential_restitution", "viscous", "contact_solve", "predicted_lever",
                      "soil_drag", "tolerance_m_s", "max_iterations", "prox_alpha", "rest_speed_m_s",
                      "rest_angular_speed_rad_s", "rest_hold_s"}),
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
