#include <toml++/toml.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "common/error.hpp"
#include "io/scene_tables.hpp"
#include "io/vector.hpp"

namespace talus::io::scene_tables {

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
                       TenDigits(g.x0_m) + " .. " + TenDigits(g.x_max_m()) + ", y " +
                       TenDigits(g.y0_m) + " .. " + TenDigits(g.y_max_m()) +
                       "), so no rock can cross it");
    for (std::size_t j = 0; j < k; ++j)
      if (lines[j].name == line.name)
        throw InputError(origin[k] + ": the name '" + line.name + "' is also that of " + origin[j] +
                         "; names must be unique");
  }
}

}  // namespace talus::io::scene_tables
