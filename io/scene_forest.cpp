#include <toml++/toml.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "common/csv_table.hpp"
#include "common/error.hpp"
#include "io/scene_tables.hpp"
#include "solver/random.hpp"

namespace talus::io::scene_tables {
namespace {

// Bounds of plausible forests (docs/scenes.md): beyond them a value is a typo or a wrong unit.
constexpr double kMaxDbh_cm = 300;              // the largest trees of the Alps are ~ 2 m
constexpr double kMaxStemsPerHa = 10000;        // one stem per m^2
constexpr double kMaxStemHeight_m = 100;
constexpr double kMaxFriction = 10;
constexpr long kMaxTrees = 10'000'000;          // 24 bytes each
constexpr double kMinDrawnDbh_cm = 1;           // a normal draw below it is set to it
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

// trees = "file.csv": one tree per row, columns x_m, y_m (the DEM's coordinates) and dbh_cm.
void ReadTrees(const Context& context, const Section& s, const Terrain& terrain,
               std::vector<Stem>* stems, SceneFile& out) {
  const std::string path = context.Resolve(s.String("trees", ""));
  const std::string key = context.Where(s.Node("trees")) + ": " + s.Key("trees");
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
      throw InputError(table.Where(row, "dbh_cm") + ": " + TenDigits(dbh_cm) +
                       " cm must be > 0 and <= " + TenDigits(kMaxDbh_cm) + " cm");
    stem.dbh_m = dbh_cm / 100;
    stem.ground_m = FootOf(terrain, stem.position_m, table.Where(row, "x_m"));
    stems->push_back(stem);
  }
  out.inputs.push_back(path);
  out.trees_file = path;
  out.trees_from_file = table.rows();
}

// stands = [{ polygon = [[x, y], ...], stems_per_ha, dbh_cm, dbh_sd_cm }]: trees drawn as a
// homogeneous Poisson process in each polygon, DBH normal (mean, spread), from the forest's seed.
void DrawStands(const Context& context, const Section& forest, const Terrain& terrain,
                std::uint64_t seed, std::vector<Stem>* stems, SceneFile& out) {
  const toml::array* list = forest.Node("stands")->as_array();
  if (!list || list->empty() || !list->is_array_of_tables())
    forest.Fail("stands", "expected a list of inline tables { polygon = [[x, y], ...], "
                          "stems_per_ha = ..., dbh_cm = ... }");
  for (std::size_t k = 0; k < list->size(); ++k) {
    const Section s(context, list->get(k)->as_table(), "forest.stands[" + std::to_string(k) + "]",
                    {"polygon", "stems_per_ha", "dbh_cm", "dbh_sd_cm"});
    for (const char* required : {"polygon", "stems_per_ha", "dbh_cm"})
      if (!s.Has(required)) s.Fail(required, "missing");
    SceneFile::ForestStand stand;
    stand.stems_per_ha = s.Number("stems_per_ha", 0);
    if (!(stand.stems_per_ha > 0 && stand.stems_per_ha <= kMaxStemsPerHa))
      s.Fail("stems_per_ha", TenDigits(stand.stems_per_ha) + " must be > 0 and <= " +
                                 TenDigits(kMaxStemsPerHa) + " stems per hectare");
    stand.dbh_cm = s.Number("dbh_cm", 0);
    if (!(stand.dbh_cm > 0 && stand.dbh_cm <= kMaxDbh_cm))
      s.Fail("dbh_cm", TenDigits(stand.dbh_cm) + " cm must be > 0 and <= " +
                           TenDigits(kMaxDbh_cm) + " cm");
    stand.dbh_sd_cm = s.Number("dbh_sd_cm", 0);
    if (!(stand.dbh_sd_cm >= 0 && stand.dbh_sd_cm <= stand.dbh_cm))
      s.Fail("dbh_sd_cm", TenDigits(stand.dbh_sd_cm) + " cm must be >= 0 and <= dbh_cm");
    const std::vector<Eigen::Vector2d> ring = PointList(s, s.Node("polygon"), s.Key("polygon"));
    if (ring.size() < 3) s.Fail("polygon", "a stand needs at least 3 points");
    stand.area_m2 = Area(ring);
    if (!(stand.area_m2 > 0)) s.Fail("polygon", "the polygon has zero area");
    const std::string where = context.Where(s.Node("polygon")) + ": " + s.Key("polygon");

    // The number of trees: Poisson with mean density * area, counted as the arrivals of a unit
    // rate process before that mean; then each tree uniform in the polygon (rejection from its
    // bounding box) with its DBH. One stream per stand.
    RockRandom random(seed, kForestStream + k);
    const double mean = stand.stems_per_ha / 1e4 * stand.area_m2;
    if (mean > kMaxTrees)
      s.Fail("stems_per_ha", "the stand would have about " + TenDigits(mean) +
                                 " trees, more than " + std::to_string(kMaxTrees));
    long count = 0;
    for (double t = -std::log1p(-random.Uniform()); t <= mean;
         t -= std::log1p(-random.Uniform()))
      ++count;
    Eigen::Vector2d lo = ring.front(), hi = ring.front();
    for (const Eigen::Vector2d& p : ring) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
    for (long n = 0; n < count; ++n) {
      Stem stem;
      do {
        stem.position_m = lo + Eigen::Vector2d(random.Uniform(), random.Uniform())
                                   .cwiseProduct(hi - lo);
      } while (!Inside(ring, stem.position_m));
      double dbh_cm = stand.dbh_cm;
      if (stand.dbh_sd_cm > 0) {  // Box-Muller
        const double u = 1 - random.Uniform(), v = random.Uniform();
        dbh_cm += stand.dbh_sd_cm * std::sqrt(-2 * std::log(u)) * std::cos(2 * M_PI * v);
      }
      stem.dbh_m = std::clamp(dbh_cm, kMinDrawnDbh_cm, kMaxDbh_cm) / 100;
      stem.ground_m = FootOf(terrain, stem.position_m, where);
      stems->push_back(stem);
    }
    stand.trees = count;
    out.stands.push_back(stand);
  }
}

}  // namespace

void LoadForest(const Context& context, const Section& s, bool given, SceneFile& out) {
  if (!given) return;
  if (!s.Has("trees") && !s.Has("stands"))
    s.Fail("trees", "a [forest] needs trees = \"trees.csv\" or stands = [{ polygon = ..., "
                    "stems_per_ha = ..., dbh_cm = ... }] (or both)");
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
  const long seed = s.Integer("seed", static_cast<long>(out.release.seed));
  if (seed < 0) s.Fail("seed", std::to_string(seed) + " must be >= 0");
  out.forest_seed = static_cast<std::uint64_t>(seed);

  std::vector<Stem> stems;
  if (s.Has("trees")) ReadTrees(context, s, out.scene.terrain, &stems, out);
  if (s.Has("stands")) DrawStands(context, s, out.scene.terrain, out.forest_seed, &stems, out);
  if (static_cast<long>(stems.size()) > kMaxTrees)
    s.Fail("stands", std::to_string(stems.size()) + " trees, more than " +
                         std::to_string(kMaxTrees));
  if (stems.empty())
    out.warnings.push_back(context.Where(s.Node("stands")) +
                           ": forest.stands: the stands drew no tree (too small or too sparse)");
  out.has_forest = true;
  out.scene.forest = Forest(std::move(stems), model);
}

}  // namespace talus::io::scene_tables
