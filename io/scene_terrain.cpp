#include <toml++/toml.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "common/closest_name.hpp"
#include "common/error.hpp"
#include "io/raster.hpp"
#include "io/scene_tables.hpp"
#include "io/vector.hpp"

namespace talus::io::scene_tables {
namespace {

namespace fs = std::filesystem;

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
      // NOLINTNEXTLINE(bugprone-integer-division): k / nx is the row, an integer on purpose
      const double y = d.y0_m + d.dy_m * static_cast<double>(k / static_cast<std::size_t>(d.nx));
      grid.index[k] = static_cast<std::uint8_t>(scene.terrain.GroundAt(x, y));
    } else {
      grid.index[k] = GroundGrid::kNoGround;
    }
  }
  if (!any)
    throw InputError(what + ": " + path + " covers no cell centre of the DEM (x " +
                     TenDigits(d.x0_m) + " .. " + TenDigits(d.x_max_m()) + ", y " +
                     TenDigits(d.y0_m) + " .. " + TenDigits(d.y_max_m()) +
                     "): every contact would get the default ground");
  scene.terrain.SetGroundGrid(std::move(grid));
  std::string why;
  if (!scene.terrain.IsValid(&why)) terrain.Fail("ground_polygons", why);
}

// [terrain] ground = "ground.tif": the raster of category codes (reprojected to the DEM's CRS when
// it has another), which must overlap the DEM and hold only codes of the ground table.
void LoadGroundRaster(const Context& context, const Section& s, SceneFile& out) {
  Scene& scene = out.scene;
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
    s.Fail("ground", path + " covers x " + TenDigits(cx0) + " .. " + TenDigits(cx1) + ", y " +
                         TenDigits(cy0) + " .. " + TenDigits(cy1) +
                         ", which does not overlap the DEM (x " + TenDigits(d.x0_m) + " .. " +
                         TenDigits(d.x_max_m()) + ", y " + TenDigits(d.y0_m) + " .. " +
                         TenDigits(d.y_max_m()) + "): every contact would get the default ground");
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
      throw InputError(what + ": " + path + " has the value " + TenDigits(v) + " (cell " +
                       std::to_string(k % static_cast<std::size_t>(codes.grid.nx)) + ", " +
                       std::to_string(k / static_cast<std::size_t>(codes.grid.nx)) +
                       " from the south-west), which is not the code of any ground category");
    grid.index[k] = static_cast<std::uint8_t>(index);
  }
  scene.terrain.SetGroundGrid(std::move(grid));
  std::string why;
  if (!scene.terrain.IsValid(&why)) s.Fail("ground", why);
}

}  // namespace

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
        "plane " + TenDigits(spec.slope_deg) + " deg, " + std::to_string(heights.grid.nx) + " x " +
        std::to_string(heights.grid.ny) + " cells of " + TenDigits(spec.cell_m) + " m";
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
        s.Fail("dem", path + " has the height " + TenDigits(dem.values[k]) + " m (cell " +
                          std::to_string(k % static_cast<std::size_t>(dem.grid.nx)) + ", " +
                          std::to_string(k / static_cast<std::size_t>(dem.grid.nx)) +
                          " from the south-west), beyond +-" + TenDigits(kMaxAbsHeight_m) +
                          " m: a nodata value the file does not declare, or not metres?");
    out.inputs.push_back(path);
    out.crs_wkt = dem.crs_wkt;
    heights.grid = dem.grid;
    heights.z_m = std::move(dem.values);
    out.terrain_description =
        fs::path(path).filename().string() + " (" + std::to_string(heights.grid.nx) + " x " +
        std::to_string(heights.grid.ny) + " cells of " + TenDigits(heights.grid.dx_m) + " m)";
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

  if (s.Has("ground")) LoadGroundRaster(context, s, out);
  if (s.Has("ground_polygons")) LoadGroundPolygons(context, s, out);
}

}  // namespace talus::io::scene_tables
