#include <toml++/toml.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <map>
#include <numbers>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "common/closest_name.hpp"
#include "common/csv_table.hpp"
#include "common/error.hpp"
#include "fieldobs/single_impacts.hpp"
#include "io/scene_tables.hpp"
#include "io/vector.hpp"

namespace talus::io::scene_tables {
namespace {

namespace fs = std::filesystem;
using ensemble::ReleaseGeometry;

// The most source cells one [release] source may give (each is a release polygon).
constexpr long kMaxSourceCells = 10'000'000;

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
  // A surveyed ground height per start (column ground_z_m) further than this from the DEM's is
  // warned of: the run starts on other terrain than the field's.
  const double ground_tolerance_m = s.Checked(
      "ground_z_tolerance_m", 1.0, [](double v) { return v > 0 && v <= 1000; },
      "must be in (0, 1000] m");
  if (s.Has("ground_z_tolerance_m") && !rows.Has("ground_z_m"))
    s.Fail("ground_z_tolerance_m", "the run table has no ground_z_m column to compare");
  const GridGeometry& g = out.scene.terrain.heights().grid;
  std::unordered_map<std::string, int> first_row;  // of each run id
  for (int k = 0; k < rows.rows(); ++k) {
    ensemble::ReleaseRun run;
    run.id = rows.Text(k, "trajectory_id");
    if (run.id.empty()) throw InputError(rows.Where(k, "trajectory_id") + ": empty");
    if (const auto [at, added] = first_row.emplace(run.id, k); !added)
      throw InputError(rows.Where(k, "trajectory_id") + ": run '" + run.id +
                       "' appears twice (first on line " + std::to_string(rows.line(at->second)) +
                       ")");
    run.xy_m = Eigen::Vector2d(rows.Number(k, "x_m"), rows.Number(k, "y_m"));
    run.z_m = rows.OptionalNumber(k, "z_m");
    run.height_m = rows.OptionalNumber(k, "height_m");
    if (run.height_m && *run.height_m < 0)
      throw InputError(rows.Where(k, "height_m") + ": must be >= 0");
    if (run.height_m && *run.height_m > kMaxReleaseHeight_m)
      throw InputError(rows.Where(k, "height_m") + ": " + TenDigits(*run.height_m) +
                       " is more than " + TenDigits(kMaxReleaseHeight_m) + " m");
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
                         TenDigits(q.norm()) + ", expected 1");
      run.orientation = q.normalized();
    }
    run.block = BlockOfRow(rows, k, block_column, out);
    double ground_m;
    if (!out.scene.terrain.Height(run.xy_m.x(), run.xy_m.y(), &ground_m))
      throw InputError(rows.Where(k, "x_m") + ": (" + TenDigits(run.xy_m.x()) + ", " +
                       TenDigits(run.xy_m.y()) +
                       ") is outside the DEM or on nodata (the DEM covers x " + TenDigits(g.x0_m) +
                       " .. " + TenDigits(g.x_max_m()) + ", y " + TenDigits(g.y0_m) + " .. " +
                       TenDigits(g.y_max_m()) + ")");
    if (run.z_m && *run.z_m - ground_m > kMaxReleaseHeight_m)
      throw InputError(rows.Where(k, "z_m") + ": " + TenDigits(*run.z_m) + " m is " +
                       TenDigits(*run.z_m - ground_m) + " m above the ground, more than " +
                       TenDigits(kMaxReleaseHeight_m) + " m");
    if (const std::optional<double> surveyed = rows.OptionalNumber(k, "ground_z_m");
        surveyed && std::abs(*surveyed - ground_m) > ground_tolerance_m)
      out.ground_mismatches.push_back({run.id, rows.Where(k, "ground_z_m"), ground_m, *surveyed});
    r.runs.push_back(run);
  }
  if (!out.ground_mismatches.empty()) {
    const auto worst = std::max_element(
        out.ground_mismatches.begin(), out.ground_mismatches.end(),
        [](const GroundMismatch& a, const GroundMismatch& b) {
          return std::abs(a.dem_z_m - a.surveyed_z_m) < std::abs(b.dem_z_m - b.surveyed_z_m);
        });
    out.warnings.push_back(
        path + ": " + std::to_string(out.ground_mismatches.size()) + " of " +
        std::to_string(rows.rows()) + " runs start where the DEM departs from the surveyed ground " +
        "(ground_z_m) by more than ground_z_tolerance_m = " + TenDigits(ground_tolerance_m) +
        " m (largest: run '" + worst->run + "', DEM " + FormatDouble(worst->dem_z_m, "%.2f") +
        " m, survey " + FormatDouble(worst->surveyed_z_m, "%.2f") +
        " m): they start on other terrain than the field's, and their scores measure the DEM as "
        "much as the model (talus validate lists them: scores.json, start_ground_mismatch)");
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
    s.Fail("at", "(" + TenDigits(at.x()) + ", " + TenDigits(at.y()) +
                     ") is outside the DEM or on nodata");
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
      throw InputError(impact.where + ": incoming speed " + TenDigits(speed) +
                       " m/s is more than " + TenDigits(kMaxSpeed_m_s) + " m/s");
    if (std::abs(impact.angular_speed_rad_s) > kMaxAngularSpeed_rad_s)
      throw InputError(rows.Where(k, columns.angular_speed) + ": more than " +
                       TenDigits(kMaxAngularSpeed_rad_s) + " rad/s");
    out.release.runs.push_back(fieldobs::SingleImpactRun(impact, out.scene.terrain, at, clearance_m,
                                                         BlockOfRow(rows, k, block_column, out)));
  }
  out.release.height_reference = ensemble::ReleaseSpec::HeightReference::kLowestPoint;
}

// [release] source = { raster = "sources.tif", slope_min_deg = ... }: source cells, each a
// release polygon (Rockyfor3D's source raster, a slope threshold for screening). The cells of the
// raster whose value is > 0 (not nodata), or without a raster every DEM cell (a square around its
// node, as the rasters Talus writes), clipped to the DEM's outermost nodes; with slope_min_deg only those
// where the terrain's slope at the cell's centre is at least that.
void LoadSourceCells(const Context& context, const Section& s, SceneFile& out,
                     std::vector<std::string>& origin) {
  const toml::node* node = s.Node("source");
  if (!node->is_table())
    s.Fail("source", "expected an inline table { raster = \"sources.tif\" } or { slope_min_deg = ... }");
  const Section v(context, node->as_table(), "release.source", {"raster", "slope_min_deg"});
  if (!v.Has("raster") && !v.Has("slope_min_deg"))
    v.Fail("raster", "missing: give raster = \"file\", slope_min_deg = ..., or both");
  const double slope_min = v.Checked(
      "slope_min_deg", 0, [](double x) { return x >= 0 && x < 90; }, "0 <= slope_min_deg < 90");
  const Terrain& terrain = out.scene.terrain;
  const GridGeometry& dem = terrain.heights().grid;
  const std::string where = context.Where(s.Node("source")) + ": " + s.Key("source");
  // The cells: the raster's, or the DEM's.
  GridGeometry grid = dem;
  std::vector<double> values;
  std::string path;
  if (v.Has("raster")) {
    path = context.Resolve(v.String("raster", ""));
    std::string reprojected_from;
    Raster raster = ReadRasterIn(path, out.crs_wkt,
                                 context.Where(v.Node("raster")) + ": " + v.Key("raster"),
                                 &reprojected_from);
    out.inputs.push_back(path);
    grid = raster.grid;
    values = std::move(raster.values);
  }
  // The terrain has heights between the DEM's outermost nodes: edge cells are cut there.
  const double xmin = dem.x0_m, xmax = dem.x_max_m(), ymin = dem.y0_m, ymax = dem.y_max_m();
  long cells = 0;
  for (int j = 0; j < grid.ny; ++j)
    for (int i = 0; i < grid.nx; ++i) {
      const std::size_t k = static_cast<std::size_t>(j) * grid.nx + i;
      if (!values.empty() && !(values[k] > 0)) continue;  // 0, negative or nodata: not a source
      const double x = grid.x0_m + i * grid.dx_m, y = grid.y0_m + j * grid.dy_m;
      const double x0 = std::max(x - 0.5 * grid.dx_m, xmin), x1 = std::min(x + 0.5 * grid.dx_m, xmax);
      const double y0 = std::max(y - 0.5 * grid.dy_m, ymin), y1 = std::min(y + 0.5 * grid.dy_m, ymax);
      if (!(x1 > x0 && y1 > y0)) continue;  // off the DEM's extent
      if (v.Has("slope_min_deg")) {
        TerrainSample sample;
        if (!terrain.Sample(0.5 * (x0 + x1), 0.5 * (y0 + y1), &sample)) continue;
        const double slope_deg = std::acos(std::clamp(sample.normal.z(), -1.0, 1.0)) * 180 / std::numbers::pi;
        if (slope_deg < slope_min) continue;
      }
      if (++cells > kMaxSourceCells)
        v.Fail(v.Has("raster") ? "raster" : "slope_min_deg",
               "more than " + std::to_string(kMaxSourceCells) +
                   " source cells: coarsen the source raster or raise slope_min_deg");
      out.release.releases.push_back(
          {ReleaseGeometry::Kind::kPolygon, {{{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}}}});
      origin.push_back(where + " (" + (path.empty() ? std::string("DEM") : path) + " cell " +
                       std::to_string(i) + ", " + std::to_string(j) + " from the south-west)");
    }
  if (cells == 0)
    v.Fail(v.Has("raster") ? "raster" : "slope_min_deg",
           "no source cell: " +
               std::string(v.Has("raster") ? "the raster has no cell > 0 on the DEM" : "") +
               std::string(v.Has("raster") && v.Has("slope_min_deg") ? " at that slope" : "") +
               std::string(!v.Has("raster") ? "no DEM cell is that steep" : ""));
}

// [release] points, lines, polygons and a vector file (with layer and where) into
// out.release.releases; returns where each came from, for errors: "<file>:<line>: <key>[k]".
std::vector<std::string> LoadReleaseGeometries(const Context& context, const Section& s,
                                               SceneFile& out) {
  ensemble::ReleaseSpec& r = out.release;
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
  if (s.Has("source")) LoadSourceCells(context, s, out, origin);
  return origin;
}

// [release] height, height reference, clip_to_dem, orientation, start velocities and seed.
void LoadReleaseStart(const Section& s, ensemble::ReleaseSpec& r) {
  r.height_m = s.Checked(
      "height_m", 1.0, [](double v) { return v >= 0; }, "must be >= 0");
  if (r.height_m > kMaxReleaseHeight_m)
    s.Fail("height_m",
           TenDigits(r.height_m) + " is more than " + TenDigits(kMaxReleaseHeight_m) + " m");
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
               "quaternion [w, x, y, z] has norm " + TenDigits(quat.norm()) + ", expected 1");
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
}

// Every point a release can start a rock from lies on valid terrain (or, with clip_to_dem, enough
// of each line and polygon does); returns the fraction of each release on the terrain.
std::vector<double> CheckReleasesOnTerrain(const std::vector<std::string>& origin,
                                           const SceneFile& out) {
  const ensemble::ReleaseSpec& r = out.release;
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
    const std::string dem = " (the DEM covers x " + TenDigits(g.x0_m) + " .. " +
                            TenDigits(g.x_max_m()) + ", y " + TenDigits(g.y0_m) + " .. " +
                            TenDigits(g.y_max_m()) + ")";
    if (!r.clip_to_dem || release.kind == ReleaseGeometry::Kind::kPoint)
      throw InputError(origin[k] + ": (" + TenDigits(v->x()) + ", " + TenDigits(v->y()) +
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
      throw InputError(origin[k] + ": the part on valid DEM cells is " + TenDigits(100 * fill) +
                       " % of its " +
                       (release.kind == ReleaseGeometry::Kind::kLine ? "length" : "bounding box") +
                       ", less than " + TenDigits(100 * ensemble::kMinPolygonFill) +
                       " %: too little to draw start points from" + dem);
  }
  return on_terrain;
}

// [release] rocks_per_m2 or rocks_per_cell (`count_key`): round(density x area on the terrain)
// rocks per polygon, at least 1.
void SetRocksByArea(const Section& s, const std::string& count_key,
                    const std::vector<std::string>& origin, const std::vector<double>& on_terrain,
                    SceneFile& out) {
  ensemble::ReleaseSpec& r = out.release;
  const GridGeometry& g = out.scene.terrain.heights().grid;
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
      s.Fail(count_key, TenDigits(n) + " rocks for " + origin[k] + ", more than " +
                            std::to_string(ensemble::ReleaseSpec::kMaxTotalRocks));
    counts.push_back(std::max(1L, static_cast<long>(n)));
  }
  r.SetRocksPerRelease(counts);
}

}  // namespace

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

// [release] volume = { distribution = "power_law", min_m3 = ..., max_m3 = ..., exponent = ... }
// (ensemble::VolumeDistribution): block sizes for release geometries, not for runs, which have
// their blocks.
void LoadVolume(const Context& context, const Section& s, ensemble::ReleaseSpec& r) {
  const toml::node* node = s.Node("volume");
  if (!node) return;
  if (!node->is_table())
    s.Fail("volume", "expected an inline table { distribution = \"power_law\", min_m3 = ..., ... }");
  if (!r.runs.empty())
    s.Fail("volume", "block sizes are for release points, lines and polygons; a run table gives "
                     "each run its block");
  const Section v(context, node->as_table(), "release.volume",
                  {"distribution", "min_m3", "max_m3", "median_m3", "sigma", "exponent"});
  const std::string name = v.String("distribution", "");
  using Kind = ensemble::VolumeDistribution::Kind;
  ensemble::VolumeDistribution& d = r.volume;
  const std::map<std::string, std::vector<std::string>> keys = {
      {"fixed", {}},
      {"uniform", {"min_m3", "max_m3"}},
      {"lognormal", {"median_m3", "sigma", "min_m3", "max_m3"}},
      {"power_law", {"min_m3", "max_m3", "exponent"}}};
  const auto known = keys.find(name);
  if (known == keys.end())
    v.Fail("distribution", "'" + name + "' is not one of fixed, uniform, lognormal, power_law");
  for (const char* key : {"min_m3", "max_m3", "median_m3", "sigma", "exponent"})
    if (v.Has(key) && std::find(known->second.begin(), known->second.end(), key) == known->second.end())
      v.Fail(key, "is not a parameter of the " + name + " distribution");
  if (name == "fixed") return;
  d.kind = name == "uniform" ? Kind::kUniform : name == "lognormal" ? Kind::kLogNormal : Kind::kPowerLaw;
  const auto required = [&v](const char* key) {
    if (!v.Has(key)) v.Fail(key, "missing");
    return v.Number(key, 0);
  };
  if (d.kind == Kind::kLogNormal) {
    d.median_m3 = required("median_m3");
    d.sigma = required("sigma");
    d.min_m3 = v.Number("min_m3", 0);
    d.max_m3 = v.Number("max_m3", std::numeric_limits<double>::infinity());
  } else {
    d.min_m3 = required("min_m3");
    d.max_m3 = required("max_m3");
    if (d.kind == Kind::kPowerLaw) d.exponent = required("exponent");
  }
  std::string why;
  if (!d.IsValid(&why)) v.FailCheck(why);
}

void LoadRelease(const Context& context, const Section& s, SceneFile& out) {
  ensemble::ReleaseSpec& r = out.release;
  const std::vector<std::string> origin = LoadReleaseGeometries(context, s, out);
  if (s.Has("runs")) {
    if (!r.releases.empty())
      s.Fail("runs", "a run table cannot be combined with points, lines, polygons or a file");
    for (const char* key : {"velocity_m_s", "angular_velocity_rad_s"})
      if (s.Has(key))
        s.Fail(key, "a run table gives each run's start velocities (columns vx_mps .. wz_radps)");
    LoadRuns(context, s, out);
  }
  if (s.Has("ground_z_tolerance_m") && !s.Has("runs"))
    s.Fail("ground_z_tolerance_m",
           "compares a run table's ground_z_m with the DEM: only with runs = \"file.csv\"");
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
  if (s.Has("source") && count_key != "rocks")
    s.Fail(count_key, "each source cell releases `rocks` rocks; give rocks with source");
  const long rocks = s.Integer("rocks", 1);
  if (rocks < 1) s.Fail("rocks", std::to_string(rocks) + " must be >= 1");
  r.rocks_per_release = rocks;
  LoadReleaseStart(s, r);
  LoadVolume(context, s, r);

  const std::vector<double> on_terrain = CheckReleasesOnTerrain(origin, out);
  if (count_key != "rocks") SetRocksByArea(s, count_key, origin, on_terrain, out);
  std::string why;
  if (!r.IsValid(&why)) s.FailCheck(why);
}

}  // namespace talus::io::scene_tables
