#include <toml++/toml.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "common/csv_table.hpp"
#include "common/error.hpp"
#include "io/raster.hpp"
#include "io/scene_tables.hpp"
#include "io/vector.hpp"
#include "solver/random.hpp"

namespace talus::io::scene_tables {
namespace {

// Bounds of plausible forests (docs/scenes.md): beyond them a value is a typo or a wrong unit.
constexpr double kMaxDbh_cm = 300;        // the largest trees of the Alps are ~ 2 m
constexpr double kMaxStemsPerHa = 10000;  // one stem per m^2
constexpr double kMaxStemHeight_m = 100;
constexpr double kMaxFriction = 10;
constexpr long kMaxTrees = 10'000'000;    // 40 bytes each
constexpr double kMaxEnergyFactor = 100;  // a species' E_max over the forest's law
constexpr double kMinDrawnDbh_cm = 1;     // a normal draw below it is set to it
// The forest's own random streams: the stand index mixed with this, so that they never coincide
// with a rock's (seed, rock) stream.
constexpr std::uint64_t kForestStream = 0x666f72657374ULL;  // "forest"

double Area(const std::vector<Eigen::Vector2d>& ring) {
  double twice = 0;
  for (std::size_t i = 0; i < ring.size(); ++i) {
    const Eigen::Vector2d& a = ring[i];
    const Eigen::Vector2d& b = ring[(i + 1) % ring.size()];
    twice += a.x() * b.y() - a.y() * b.x();
  }
  return 0.5 * std::abs(twice);
}

// Even-odd rule.
bool Inside(const std::vector<Eigen::Vector2d>& ring, const Eigen::Vector2d& p) {
  bool in = false;
  for (std::size_t i = 0, j = ring.size() - 1; i < ring.size(); j = i++) {
    const Eigen::Vector2d &a = ring[i], &b = ring[j];
    if ((a.y() > p.y()) != (b.y() > p.y()) &&
        p.x() < (b.x() - a.x()) * (p.y() - a.y()) / (b.y() - a.y()) + a.x())
      in = !in;
  }
  return in;
}

// The terrain's height under a tree, or an error naming `where` and the DEM's extent.
double FootOf(const Terrain& terrain, const Eigen::Vector2d& p, const std::string& where) {
  double z = 0;
  if (terrain.Height(p.x(), p.y(), &z)) return z;
  const GridGeometry& g = terrain.heights().grid;
  throw InputError(where + ": the tree at (" + TenDigits(p.x()) + ", " + TenDigits(p.y()) +
                   ") is off the DEM or on nodata; the DEM covers x " + TenDigits(g.x0_m) + " .. " +
                   TenDigits(g.x_max_m()) + ", y " + TenDigits(g.y0_m) + " .. " +
                   TenDigits(g.y_max_m()) +
                   ": trees are in the DEM's coordinates (a file in another CRS must be "
                   "reprojected first)");
}

bool IsCsv(const std::string& path) {
  if (path.size() < 4) return false;
  std::string ext = path.substr(path.size() - 4);
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return std::tolower(c); });
  return ext == ".csv";
}

std::string DbhBounds(double dbh_cm) {
  return TenDigits(dbh_cm) + " cm must be > 0 and <= " + TenDigits(kMaxDbh_cm) + " cm";
}

// [forest.species.<name>]: each species' breaking-energy law, in name order (toml++'s order).
std::vector<TreeSpecies> ReadSpecies(const Context& context, const Section& forest) {
  std::vector<TreeSpecies> species;
  if (!forest.Has("species")) return species;
  const toml::table* table = forest.Node("species")->as_table();
  if (!table)
    forest.Fail("species",
                "expected tables [forest.species.<name>], each with energy_factor or "
                "energy_coefficient_j and/or energy_exponent");
  for (const auto& [key, node] : *table) {
    const std::string name = forest.Key("species") + "." + std::string(key.str());
    if (!node.is_table())
      context.Fail(&node, name,
                   "expected a table [" + name +
                       "] with energy_factor or energy_coefficient_j "
                       "and/or energy_exponent");
    const Section s(context, node.as_table(), name,
                    {"energy_factor", "energy_coefficient_j", "energy_exponent"});
    TreeSpecies& t = species.emplace_back();
    t.name = key.str();
    const bool own_law = s.Has("energy_coefficient_j") || s.Has("energy_exponent");
    if (s.Has("energy_factor") && own_law)
      s.Fail("energy_factor",
             "a species gives energy_factor (E_max = factor x the forest's law) or a law of its "
             "own (energy_coefficient_j and/or energy_exponent), not both");
    if (!s.Has("energy_factor") && !own_law)
      s.Fail("energy_factor",
             "missing: give energy_factor (E_max = factor x the forest's law) or "
             "energy_coefficient_j and/or energy_exponent (a law of its own)");
    t.energy_factor = s.Number("energy_factor", t.energy_factor);
    RequireWithin(s, "energy_factor", t.energy_factor, 0, kMaxEnergyFactor, "");
    if (s.Has("energy_coefficient_j")) t.energy_coefficient_J = s.Number("energy_coefficient_j", 0);
    if (s.Has("energy_exponent")) {
      t.energy_exponent = s.Number("energy_exponent", 0);
      RequireWithin(s, "energy_exponent", *t.energy_exponent, 0, 5, "");
    }
    std::string why;
    if (!t.IsValid(&why)) s.FailCheck(why);
  }
  return species;
}

// The species that trees and stands name, looked up in [forest.species]; remembers which were
// named, and where a file named species that the scene does not declare.
class SpeciesNames {
 public:
  explicit SpeciesNames(const std::vector<TreeSpecies>& species)
      : species_(species), used_(species.size(), false) {}

  bool any() const { return !species_.empty(); }

  // -1 for an empty name, else the index of the species `name`. Throws InputError
  // "<where>: species '<name>' is not declared ..." listing the declared ones.
  int Find(const std::string& name, const std::string& where) {
    if (name.empty()) return -1;
    std::string declared;
    for (std::size_t k = 0; k < species_.size(); ++k) {
      if (species_[k].name == name) {
        used_[k] = true;
        return static_cast<int>(k);
      }
      declared += (k ? ", '" : "'") + species_[k].name + "'";
    }
    throw InputError(where + ": species '" + name + "' is not declared in [forest.species] " +
                     "(declared: " + (declared.empty() ? "none" : declared) + ")");
  }
  // As Find, for a name from a tree or stand file: without [forest.species] a file's species are
  // ignored (-1, and a warning naming the first), so that inventories with a species column load
  // as before.
  int FindInFile(const std::string& name, const std::string& where) {
    if (!any()) {
      if (!name.empty() && ignored_.empty()) ignored_ = where;
      return -1;
    }
    return Find(name, where);
  }

  // Warnings: species of [forest.species] (the table of `forest`) that no tree or stand named,
  // and a file's species ignored.
  void Warn(const Context& context, const Section& forest,
            std::vector<std::string>* warnings) const {
    for (std::size_t k = 0; k < species_.size(); ++k)
      if (!used_[k]) {
        const std::string& name = species_[k].name;
        warnings->push_back(context.Where(forest.Node("species")->as_table()->get(name)) + ": " +
                            forest.Key("species") + "." + name +
                            ": forest: declared, but no tree or stand names it");
      }
    if (!ignored_.empty())
      warnings->push_back(ignored_ +
                          ": forest: names a species, but the scene declares none "
                          "([forest.species]): the file's species are ignored and every stem "
                          "takes the forest's breaking-energy law");
  }

 private:
  const std::vector<TreeSpecies>& species_;
  std::vector<bool> used_;
  std::string ignored_;
};

// trees = "file": a CSV file, one tree per row with columns x_m, y_m (the DEM's coordinates),
// dbh_cm and optionally species; or any point vector file GDAL reads, reprojected to the DEM's
// CRS, its DBH (cm) in the attribute dbh_field and its species in species_field.
void ReadTrees(const Context& context, const Section& s, const Terrain& terrain,
               const std::string& crs_wkt, SpeciesNames& names, std::vector<Stem>* stems,
               SceneFile& out) {
  const std::string path = context.Resolve(s.String("trees", ""));
  const std::string key = context.Where(s.Node("trees")) + ": " + s.Key("trees");
  const std::size_t first = stems->size();
  if (IsCsv(path)) {
    if (s.Has("dbh_field"))
      s.Fail("dbh_field",
             "a CSV tree list has its DBH in the column dbh_cm; dbh_field names the "
             "attribute of a vector file");
    if (s.Has("species_field"))
      s.Fail("species_field",
             "a CSV tree list has its species in the column species; species_field names the "
             "attribute of a vector file");
    CsvTable table = [&] {
      try {
        return CsvTable::Read(path);
      } catch (const InputError& e) {
        throw InputError(key + ": " + e.what());
      }
    }();
    table.Require({"x_m", "y_m", "dbh_cm"});
    if (table.rows() == 0) throw InputError(key + ": " + path + " has no trees (no rows)");
    if (table.rows() > kMaxTrees)
      throw InputError(key + ": " + path + " has " + std::to_string(table.rows()) +
                       " trees, more than " + std::to_string(kMaxTrees));
    for (int row = 0; row < table.rows(); ++row) {
      Stem stem;
      stem.position_m = {table.Number(row, "x_m"), table.Number(row, "y_m")};
      const double dbh_cm = table.Number(row, "dbh_cm");
      if (!(dbh_cm > 0 && dbh_cm <= kMaxDbh_cm))
        throw InputError(table.Where(row, "dbh_cm") + ": " + DbhBounds(dbh_cm));
      stem.dbh_m = dbh_cm / 100;
      stem.ground_m = FootOf(terrain, stem.position_m, table.Where(row, "x_m"));
      stem.species = names.FindInFile(table.Empty(row, "species") ? "" : table.Text(row, "species"),
                                      table.Where(row, "species"));
      stems->push_back(stem);
    }
  } else {
    const std::string field = s.String("dbh_field", "dbh_cm");
    const std::string species_field = s.String("species_field", "species");
    if (s.Has("species_field") && !names.any())
      s.Fail("species_field", "the scene declares no species ([forest.species.<name>])");
    for (const TreePoint& t :
         ReadTreePoints(path, crs_wkt, field, species_field, s.Has("species_field"), key)) {
      if (!(std::isfinite(t.dbh_cm) && t.dbh_cm > 0 && t.dbh_cm <= kMaxDbh_cm))
        throw InputError(t.where + ": " + field + " = " + DbhBounds(t.dbh_cm));
      if (static_cast<long>(stems->size() - first) >= kMaxTrees)
        throw InputError(key + ": " + path + " has more than " + std::to_string(kMaxTrees) +
                         " trees");
      stems->push_back(
          Stem{t.xy_m, t.dbh_cm / 100, FootOf(terrain, t.xy_m, t.where),
               names.FindInFile(t.species.value_or(""), t.where + ": " + species_field)});
    }
  }
  out.inputs.push_back(path);
  out.trees_file = path;
  out.trees_from_file = static_cast<long>(stems->size() - first);
}

// What is wrong with a stand's numbers, as {key, reason}; {"", ""} when nothing.
std::pair<std::string, std::string> StandProblem(const SceneFile::ForestStand& stand) {
  if (!(stand.stems_per_ha > 0 && stand.stems_per_ha <= kMaxStemsPerHa))
    return {"stems_per_ha", TenDigits(stand.stems_per_ha) + " must be > 0 and <= " +
                                TenDigits(kMaxStemsPerHa) + " stems per hectare"};
  if (!(stand.dbh_cm > 0 && stand.dbh_cm <= kMaxDbh_cm)) return {"dbh_cm", DbhBounds(stand.dbh_cm)};
  if (!(stand.dbh_sd_cm >= 0 && stand.dbh_sd_cm <= stand.dbh_cm))
    return {"dbh_sd_cm", TenDigits(stand.dbh_sd_cm) + " cm must be >= 0 and <= dbh_cm"};
  if (!(stand.area_m2 > 0)) return {"polygon", "the polygon has zero area"};
  const double mean = stand.stems_per_ha / 1e4 * stand.area_m2;
  if (mean > kMaxTrees)
    return {"stems_per_ha", "the stand would have about " + TenDigits(mean) + " trees, more than " +
                                std::to_string(kMaxTrees)};
  return {"", ""};
}

// Area of a polygon with holes: the outer ring's less the holes'.
double AreaOf(const std::vector<std::vector<Eigen::Vector2d>>& rings) {
  double area = 0;
  for (std::size_t r = 0; r < rings.size(); ++r) area += (r == 0 ? 1 : -1) * Area(rings[r]);
  return area;
}

// Even-odd over all rings (holes excluded).
bool InsideRings(const std::vector<std::vector<Eigen::Vector2d>>& rings, const Eigen::Vector2d& p) {
  bool in = false;
  for (const auto& ring : rings)
    if (Inside(ring, p)) in = !in;
  return in;
}

// A stand's trees: a homogeneous Poisson process in the polygon -- the count Poisson with mean
// density * area, counted as the arrivals of a unit-rate process before that mean; each tree
// uniform in the polygon (rejection from its bounding box) -- with a normal DBH (mean, spread),
// clamped to kMinDrawnDbh_cm .. kMaxDbh_cm, and the stand's species. From its own stream (seed,
// kForestStream + stream).
void DrawStand(const std::vector<std::vector<Eigen::Vector2d>>& rings, int species,
               std::uint64_t seed, std::uint64_t stream, const Terrain& terrain,
               const std::string& where, SceneFile::ForestStand* stand, std::vector<Stem>* stems) {
  RockRandom random(seed, kForestStream + stream);
  const double mean = stand->stems_per_ha / 1e4 * stand->area_m2;
  long count = 0;
  for (double t = -std::log1p(-random.Uniform()); t <= mean; t -= std::log1p(-random.Uniform()))
    ++count;
  Eigen::Vector2d lo = rings.front().front(), hi = lo;
  for (const Eigen::Vector2d& p : rings.front()) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  for (long n = 0; n < count; ++n) {
    Stem stem;
    do {
      stem.position_m =
          lo + Eigen::Vector2d(random.Uniform(), random.Uniform()).cwiseProduct(hi - lo);
    } while (!InsideRings(rings, stem.position_m));
    double dbh_cm = stand->dbh_cm;
    if (stand->dbh_sd_cm > 0) {  // Box-Muller
      const double u = 1 - random.Uniform(), v = random.Uniform();
      dbh_cm += stand->dbh_sd_cm * std::sqrt(-2 * std::log(u)) * std::cos(2 * M_PI * v);
    }
    stem.dbh_m = std::clamp(dbh_cm, kMinDrawnDbh_cm, kMaxDbh_cm) / 100;
    stem.ground_m = FootOf(terrain, stem.position_m, where);
    stem.species = species;
    stems->push_back(stem);
  }
  stand->trees = count;
}

// One stand as given: its rings (outer, then holes; in the DEM's CRS), its numbers, its species
// (an index into ForestModel::species, -1: none) and where it was given (for errors).
struct StandInput {
  std::vector<std::vector<Eigen::Vector2d>> rings;
  SceneFile::ForestStand stand;
  int species = -1;
  std::string where;
};

// stands = [{ polygon = [[x, y], ...], stems_per_ha, dbh_cm, dbh_sd_cm, species }] (or
// [[forest.stands]] tables), then the polygons of stands_file, each checked.
std::vector<StandInput> ReadStands(const Context& context, const Section& forest,
                                   const std::string& crs_wkt, SpeciesNames& names,
                                   SceneFile& out) {
  std::vector<StandInput> stands;
  if (forest.Has("stands")) {
    const toml::array* list = forest.Node("stands")->as_array();
    if (!list || list->empty() || !list->is_array_of_tables())
      forest.Fail("stands",
                  "expected a list of tables { polygon = [[x, y], ...], "
                  "stems_per_ha = ..., dbh_cm = ... }");
    for (std::size_t k = 0; k < list->size(); ++k) {
      const Section s(context, list->get(k)->as_table(), "forest.stands[" + std::to_string(k) + "]",
                      {"polygon", "stems_per_ha", "dbh_cm", "dbh_sd_cm", "species"});
      for (const char* required : {"polygon", "stems_per_ha", "dbh_cm"})
        if (!s.Has(required)) s.Fail(required, "missing");
      StandInput& input = stands.emplace_back();
      SceneFile::ForestStand& stand = input.stand;
      stand.stems_per_ha = s.Number("stems_per_ha", 0);
      stand.dbh_cm = s.Number("dbh_cm", 0);
      stand.dbh_sd_cm = s.Number("dbh_sd_cm", 0);
      input.rings = {PointList(s, s.Node("polygon"), s.Key("polygon"))};
      if (input.rings.front().size() < 3) s.Fail("polygon", "a stand needs at least 3 points");
      stand.area_m2 = AreaOf(input.rings);
      if (const auto [key, why] = StandProblem(stand); !key.empty()) s.Fail(key, why);
      const std::string species = s.String("species", "");
      input.species =
          names.Find(species, context.Where(s.Node("species")) + ": " + s.Key("species"));
      if (input.species >= 0) stand.species = species;
      input.where = context.Where(s.Node("polygon")) + ": " + s.Key("polygon");
    }
  }
  if (forest.Has("stands_file")) {
    const std::string path = context.Resolve(forest.String("stands_file", ""));
    const std::string key =
        context.Where(forest.Node("stands_file")) + ": " + forest.Key("stands_file");
    for (const StandPolygon& polygon : ReadStandPolygons(path, crs_wkt, key)) {
      StandInput& input = stands.emplace_back();
      SceneFile::ForestStand& stand = input.stand;
      stand.stems_per_ha = polygon.stems_per_ha;
      stand.dbh_cm = polygon.dbh_cm;
      stand.dbh_sd_cm = polygon.dbh_sd_cm;
      if (polygon.rings.empty() || polygon.rings.front().size() < 3)
        throw InputError(polygon.where + ": a stand needs at least 3 points");
      input.rings = polygon.rings;
      stand.area_m2 = AreaOf(polygon.rings);
      if (const auto [field, why] = StandProblem(stand); !field.empty())
        throw InputError(polygon.where + ": " + field + ": " + why);
      input.species = names.FindInFile(polygon.species.value_or(""), polygon.where + ": species");
      if (input.species >= 0) stand.species = *polygon.species;
      input.where = polygon.where;
    }
    out.inputs.push_back(path);
    out.stands_file = path;
  }
  return stands;
}

// model = "trees": each stand's trees drawn, stand k from stream k.
void DrawStands(std::vector<StandInput>& stands, const Terrain& terrain, std::uint64_t seed,
                std::vector<Stem>* stems, SceneFile& out) {
  for (std::size_t k = 0; k < stands.size(); ++k) {
    StandInput& input = stands[k];
    DrawStand(input.rings, input.species, seed, k, terrain, input.where, &input.stand, stems);
    out.stands.push_back(input.stand);
  }
}

// A raster of the drag model read onto the DEM's nodes: each node takes the value of the raster
// cell holding it (NaN off the raster or on nodata). Reprojected to the DEM's CRS first when it has
// another (as the ground raster); it must overlap the DEM.
std::vector<double> RasterOnDem(const Context& context, const Section& s, const std::string& key,
                                const GridGeometry& dem, SceneFile& out, std::string* path) {
  *path = context.Resolve(s.String(key, ""));
  const std::string what = context.Where(s.Node(key)) + ": " + s.Key(key);
  std::string reprojected_from;
  const Raster raster = ReadRasterIn(*path, out.crs_wkt, what, &reprojected_from);
  if (!reprojected_from.empty())
    out.warnings.push_back(what + ": reprojected from " + DescribeCrs(reprojected_from) +
                           " to the DEM's CRS (nearest neighbour)");
  const GridGeometry& g = raster.grid;
  std::vector<double> values(static_cast<std::size_t>(dem.nx) * dem.ny,
                             std::numeric_limits<double>::quiet_NaN());
  bool overlaps = false;
  for (int j = 0; j < dem.ny; ++j)
    for (int i = 0; i < dem.nx; ++i) {
      const double u = std::floor((dem.x0_m + i * dem.dx_m - g.x0_m) / g.dx_m + 0.5);
      const double v = std::floor((dem.y0_m + j * dem.dy_m - g.y0_m) / g.dy_m + 0.5);
      if (!(u >= 0 && u < g.nx && v >= 0 && v < g.ny)) continue;
      overlaps = true;
      values[static_cast<std::size_t>(j) * dem.nx + i] =
          raster.values[static_cast<std::size_t>(v) * g.nx + static_cast<std::size_t>(u)];
    }
  if (!overlaps)
    s.Fail(key, *path + " covers x " + TenDigits(g.x0_m - 0.5 * g.dx_m) + " .. " +
                    TenDigits(g.x_max_m() + 0.5 * g.dx_m) + ", y " +
                    TenDigits(g.y0_m - 0.5 * g.dy_m) + " .. " +
                    TenDigits(g.y_max_m() + 0.5 * g.dy_m) + ", none of the DEM (x " +
                    TenDigits(dem.x0_m) + " .. " + TenDigits(dem.x_max_m()) + ", y " +
                    TenDigits(dem.y0_m) + " .. " + TenDigits(dem.y_max_m()) + ")");
  out.inputs.push_back(*path);
  return values;
}

// "(x, y)" of DEM node k, for errors.
std::string NodeAt(const GridGeometry& g, std::size_t k) {
  const double x = g.x0_m + static_cast<double>(k % g.nx) * g.dx_m;
  const double y = g.y0_m + static_cast<double>(k / g.nx) * g.dy_m;
  std::string text = "(";
  text += TenDigits(x);
  text += ", ";
  text += TenDigits(y);
  text += ")";
  return text;
}

// model = "drag": the stands on the DEM's nodes (a node takes the stand of the last polygon holding
// it, over the rasters' stand there) as a ForestDrag of the model's breaking energy (each stand's
// species' law) and height. The rasters: stems_per_ha_raster (nodata or 0: no forest) and
// dbh_raster (cm, where there are stems), their stands of the species raster_species; each
// distinct pair of values is a stand.
ForestDrag BuildDragLayer(const Context& context, const Section& s,
                          const std::vector<StandInput>& stands, const ForestModel& model,
                          SpeciesNames& names, SceneFile& out) {
  const GridGeometry& dem = out.scene.terrain.heights().grid;
  std::vector<DragStand> list;
  std::vector<int> cells(static_cast<std::size_t>(dem.nx) * dem.ny, -1);
  if (s.Has("stems_per_ha_raster") != s.Has("dbh_raster"))
    s.Fail(s.Has("dbh_raster") ? "dbh_raster" : "stems_per_ha_raster",
           "stems_per_ha_raster and dbh_raster go together: a stand needs both its density and "
           "its DBH");
  if (s.Has("raster_species") && !s.Has("stems_per_ha_raster"))
    s.Fail("raster_species",
           "names the species of the stands of stems_per_ha_raster and dbh_raster, which the "
           "scene does not give");
  if (s.Has("stems_per_ha_raster")) {
    out.forest_raster_species = s.String("raster_species", "");
    const int species =
        names.Find(out.forest_raster_species,
                   context.Where(s.Node("raster_species")) + ": " + s.Key("raster_species"));
    const std::vector<double> density =
        RasterOnDem(context, s, "stems_per_ha_raster", dem, out, &out.forest_density_raster);
    const std::vector<double> dbh =
        RasterOnDem(context, s, "dbh_raster", dem, out, &out.forest_dbh_raster);
    std::map<std::pair<double, double>, int> index;
    for (std::size_t k = 0; k < cells.size(); ++k) {
      const double n = density[k];
      if (std::isnan(n) || n == 0) continue;
      if (!(n > 0 && n <= kMaxStemsPerHa))
        s.Fail("stems_per_ha_raster", out.forest_density_raster + ": " + TenDigits(n) +
                                          " stems per hectare at " + NodeAt(dem, k) +
                                          " must be > 0 and <= " + TenDigits(kMaxStemsPerHa) +
                                          " (nodata or 0: no forest)");
      if (!(dbh[k] > 0 && dbh[k] <= kMaxDbh_cm))
        s.Fail("dbh_raster", out.forest_dbh_raster + ": DBH " + TenDigits(dbh[k]) + " cm at " +
                                 NodeAt(dem, k) + ", where " + out.forest_density_raster +
                                 " has stems, must be > 0 and <= " + TenDigits(kMaxDbh_cm) + " cm");
      auto [it, added] = index.try_emplace({n, dbh[k]}, static_cast<int>(list.size()));
      if (added)
        list.push_back(
            DragStand{n / 1e4, dbh[k] / 100, model.BreakingEnergy_J(dbh[k] / 100, species)});
      cells[k] = it->second;
    }
  }
  if (!stands.empty()) {
    std::vector<std::vector<std::vector<Eigen::Vector2d>>> rings;
    std::vector<int> burn;
    for (const StandInput& input : stands) {
      rings.push_back(input.rings);
      burn.push_back(static_cast<int>(list.size()));
      const double dbh_m = input.stand.dbh_cm / 100;
      list.push_back(DragStand{input.stand.stems_per_ha / 1e4, dbh_m,
                               model.BreakingEnergy_J(dbh_m, input.species)});
      out.stands.push_back(input.stand);
      if (input.stand.dbh_sd_cm > 0)
        out.warnings.push_back(input.where +
                               ": forest: dbh_sd_cm is not used by model = \"drag\", which takes "
                               "the mean DBH");
    }
    const std::vector<int> burnt = RasterisePolygons(dem, rings, burn);
    for (std::size_t k = 0; k < cells.size(); ++k)
      if (burnt[k] >= 0) cells[k] = burnt[k];
  }
  out.forest_drag_cells = std::count_if(cells.begin(), cells.end(), [](int k) { return k >= 0; });
  if (out.forest_drag_cells == 0)
    out.warnings.push_back(context.Where(s.Node("model")) +
                           ": forest: no node of the DEM lies in a stand: the drag layer acts "
                           "nowhere");
  return ForestDrag(dem, std::move(cells), std::move(list), model.stem_height_m);
}

}  // namespace

void LoadForest(const Context& context, const Section& s, bool given, SceneFile& out) {
  if (!given) return;
  const std::string model_name = s.String("model", "trees");
  if (model_name != "trees" && model_name != "drag")
    s.Fail("model", "unknown forest model '" + model_name +
                        "': \"trees\" (explicit stems, the default) or \"drag\" (a drag layer "
                        "from the stands' density and DBH)");
  const bool drag = model_name == "drag";
  if (drag) {
    for (const char* key : {"trees", "dbh_field", "species_field", "friction", "seed"})
      if (s.Has(key))
        s.Fail(key, std::string("model = \"drag\" has no explicit trees: ") + key +
                        " is for model = \"trees\"");
    if (!s.Has("stands") && !s.Has("stands_file") && !s.Has("stems_per_ha_raster"))
      s.Fail("model",
             "model = \"drag\" needs stands = [{ polygon = ..., stems_per_ha = ..., dbh_cm = ... "
             "}], stands_file = \"stands.gpkg\" or stems_per_ha_raster and dbh_raster (or "
             "several)");
  } else {
    for (const char* key : {"stems_per_ha_raster", "dbh_raster", "raster_species"})
      if (s.Has(key))
        s.Fail(key, std::string(key) +
                        " is for model = \"drag\"; explicit trees come from trees, "
                        "stands or stands_file");
    if (!s.Has("trees") && !s.Has("stands") && !s.Has("stands_file"))
      s.Fail("trees",
             "a [forest] needs trees = \"trees.csv\", stands = [{ polygon = ..., "
             "stems_per_ha = ..., dbh_cm = ... }] or stands_file = \"stands.gpkg\" (or "
             "several)");
  }
  ForestModel model;
  model.stem_height_m = s.Number("stem_height_m", model.stem_height_m);
  RequireWithin(s, "stem_height_m", model.stem_height_m, 0, kMaxStemHeight_m, "m");
  model.friction = s.Number("friction", model.friction);
  RequireWithin(s, "friction", model.friction, 0, kMaxFriction, "");
  model.energy_coefficient_J = s.Number("energy_coefficient_j", model.energy_coefficient_J);
  model.energy_exponent = s.Number("energy_exponent", model.energy_exponent);
  RequireWithin(s, "energy_exponent", model.energy_exponent, 0, 5, "");
  std::string why;
  if (!model.IsValid(&why)) s.FailCheck(why);
  model.species = ReadSpecies(context, s);
  SpeciesNames names(model.species);
  out.forest_model = model_name;
  std::vector<StandInput> stands = ReadStands(context, s, out.crs_wkt, names, out);
  if (drag) {
    out.scene.forest_drag = BuildDragLayer(context, s, stands, model, names, out);
    if (!out.scene.forest_drag.IsValid(&why)) s.Fail("model", why);
    out.forest_drag_model = model;
    names.Warn(context, s, &out.warnings);
    return;
  }
  const long seed = s.Integer("seed", static_cast<long>(out.release.seed));
  if (seed < 0) s.Fail("seed", std::to_string(seed) + " must be >= 0");
  out.forest_seed = static_cast<std::uint64_t>(seed);

  std::vector<Stem> stems;
  if (s.Has("trees")) ReadTrees(context, s, out.scene.terrain, out.crs_wkt, names, &stems, out);
  DrawStands(stands, out.scene.terrain, out.forest_seed, &stems, out);
  if (static_cast<long>(stems.size()) > kMaxTrees)
    s.Fail("stands",
           std::to_string(stems.size()) + " trees, more than " + std::to_string(kMaxTrees));
  if (stems.empty())
    out.warnings.push_back(context.Where(s.Node(s.Has("stands") ? "stands" : "stands_file")) +
                           ": forest: the stands drew no tree (too small or too sparse)");
  names.Warn(context, s, &out.warnings);
  out.has_forest = true;
  out.scene.forest = Forest(std::move(stems), model);
}

}  // namespace talus::io::scene_tables
