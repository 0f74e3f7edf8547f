#include <toml++/toml.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <string>
#include <vector>

#include "common/error.hpp"
#include "io/scene_tables.hpp"
#include "io/vector.hpp"

namespace talus::io::scene_tables {
namespace {

// Bounds of plausible barriers (docs/scenes.md): beyond them a value is a typo or a wrong unit.
constexpr double kMaxBarrierHeight_m = 100;
constexpr double kMaxCapacity_kJ = 1e6;

// Where the polyline leaves the DEM or crosses nodata (sampled every half cell), or nullptr.
bool FirstPointOffDem(const Terrain& terrain, const std::vector<Eigen::Vector2d>& vertices,
                      Eigen::Vector2d* off) {
  const GridGeometry& g = terrain.heights().grid;
  const double spacing_m = 0.5 * std::min(g.dx_m, g.dy_m);
  for (std::size_t v = 1; v < vertices.size(); ++v) {
    const Eigen::Vector2d p = vertices[v - 1], q = vertices[v];
    const double n = std::min(1e6, std::ceil((q - p).norm() / spacing_m));
    for (double i = 0; i <= n; ++i) {
      const Eigen::Vector2d x = p + (n > 0 ? i / n : 0.0) * (q - p);
      double z = 0;
      if (terrain.Height(x.x(), x.y(), &z)) continue;
      *off = x;
      return true;
    }
  }
  return false;
}

// A number from a feature's attribute: numeric fields as they are, text fields when the whole
// text is a number; NaN otherwise.
double NumberOf(const FeatureValue& v) {
  if (v.kind == FeatureValue::Kind::kNumber) return v.number;
  if (v.kind != FeatureValue::Kind::kText || v.text.empty())
    return std::numeric_limits<double>::quiet_NaN();
  // std::from_chars: no locale, no hexadecimal, no surrounding blanks.
  double number = 0;
  const char* first = v.text.data();
  const char* last = first + v.text.size();
  const auto [end, error] = std::from_chars(first, last, number);
  return error == std::errc() && end == last ? number : std::numeric_limits<double>::quiet_NaN();
}

// "<where>: <field>" and why a feature's attribute has no usable value, or "" when it has one.
std::string Missing(const FeatureValue& v, const std::string& field) {
  if (v.kind == FeatureValue::Kind::kNoField)
    return "no attribute '" + field + "' (the attributes are: " + v.fields + ")";
  if (v.kind == FeatureValue::Kind::kNull || v.text.empty())
    return "attribute '" + field + "' is empty";
  return "";
}

// height_field, capacity_field, type_field of a file's [[barriers]] table: each line feature's
// own height (m), capacity (kJ) and type instead of the table's. Errors name the feature and the
// attribute. In a file a 0 is refused along with negative values: GIS tools fill unset numeric
// attributes with 0, and a height of 0 from a table is the deliberate way to ask for it.
void ApplyFeatureAttributes(const std::vector<std::string>& fields,
                            const std::vector<FeatureValue>& values, const std::string& where,
                            Barrier* b) {
  for (std::size_t k = 0; k < fields.size(); ++k) {
    const std::string& field = fields[k];
    if (field.empty()) continue;
    const FeatureValue& v = values[k];
    if (const std::string why = Missing(v, field); !why.empty())
      throw InputError(where + ": " + why);
    if (k == 2) {
      if (!ParseBarrierType(v.text, &b->type))
        throw InputError(where + ": attribute '" + field + "' is '" + v.text +
                         "', not a barrier type: expected flexible_net, rigid_wall or dam");
      continue;
    }
    const double number = NumberOf(v);
    const bool height = k == 0;
    const double max = height ? kMaxBarrierHeight_m : kMaxCapacity_kJ;
    const char* unit = height ? "m" : "kJ";
    if (!(number > 0 && number <= max))
      throw InputError(where + ": attribute '" + field + "' is " + v.text + ": the " +
                       (height ? "height" : "capacity") +
                       " must be a number > 0 and <= " + TenDigits(max) + " " + unit +
                       (height && number == 0
                            ? " (a barrier only rocks touching the ground meet: height_m = 0 in "
                              "its own table)"
                            : ""));
    if (height)
      b->height_m = number;
    else
      b->capacity_J = 1000 * number;
  }
}

}  // namespace

// [[barriers]]: barriers that act on the rocks (docs/scenes.md, docs/model.md "Barriers"), each
// a `line` (named by `name`) or the line features of a vector `file` (named by `name_field`),
// with the table's type, height and capacity.
void LoadBarriers(const Context& context, const toml::node* node, SceneFile& out) {
  if (!node) return;
  const toml::array* tables = node->as_array();
  if (!tables || tables->empty() || !tables->is_array_of_tables())
    context.Fail(node, "barriers",
                 "expected [[barriers]] tables (name, type, line, height_m, capacity_kj)");
  std::vector<Barrier>& barriers = out.scene.barriers;
  std::vector<std::string> origin;  // "<file>:<line>: barriers[k]" of each barrier, for errors
  for (std::size_t k = 0; k < tables->size(); ++k) {
    const std::string key = "barriers[" + std::to_string(k) + "]";
    const Section s(context, tables->get(k)->as_table(), key,
                    {"name", "type", "line", "file", "name_field", "height_m", "capacity_kj",
                     "height_field", "capacity_field", "type_field"});
    if (s.Has("line") == s.Has("file"))
      s.Fail("line", "give either a line ([[x, y], ...]) or a vector file of lines (file)");
    if (s.Has("name_field") && !s.Has("file"))
      s.Fail("name_field", "only the lines of a vector file ('file') are named by a name_field");
    // Per-feature attributes of a file, in the order ApplyFeatureAttributes reads them; each
    // replaces its table key.
    const std::vector<std::pair<std::string, std::string>> attribute_keys = {
        {"height_field", "height_m"}, {"capacity_field", "capacity_kj"}, {"type_field", "type"}};
    std::vector<std::string> fields;
    for (const auto& [field_key, table_key] : attribute_keys) {
      if (s.Has(field_key) && !s.Has("file"))
        s.Fail(field_key, "only the line features of a vector file ('file') have attributes");
      if (s.Has(field_key) && s.Has(table_key))
        s.Fail(table_key,
               "give " + table_key + " or " + field_key + " (each feature's own), not both");
      fields.push_back(s.Has(field_key) ? s.String(field_key, "") : "");
      if (s.Has(field_key) && fields.back().empty())
        s.Fail(field_key, "the attribute name is empty");
    }
    Barrier b;
    if (fields[2].empty()) {
      if (!s.Has("type")) s.Fail("type", "missing: \"flexible_net\", \"rigid_wall\" or \"dam\"");
      const std::string type = s.String("type", "");
      if (!ParseBarrierType(type, &b.type))
        s.Fail("type", "unknown barrier type '" + type +
                           "': expected \"flexible_net\", \"rigid_wall\" or \"dam\"");
    }
    if (fields[0].empty()) {
      if (!s.Has("height_m"))
        s.Fail("height_m", "missing: the barrier's height above the terrain (m)");
      b.height_m = s.Number("height_m", 0);
      if (!std::isfinite(b.height_m) || b.height_m < 0)
        s.Fail("height_m", TenDigits(b.height_m) + " m: the height must be >= 0 m");
      RequireWithin(s, "height_m", b.height_m, 0, kMaxBarrierHeight_m, "m");
    }
    if (fields[1].empty()) {
      if (!s.Has("capacity_kj"))
        s.Fail("capacity_kj", "missing: the energy the barrier absorbs (kJ)");
      const double capacity_kJ = s.Number("capacity_kj", 0);
      if (!std::isfinite(capacity_kJ) || capacity_kJ <= 0)
        s.Fail("capacity_kj", TenDigits(capacity_kJ) + " kJ: the capacity must be > 0 kJ");
      RequireWithin(s, "capacity_kj", capacity_kJ, 0, kMaxCapacity_kJ, "kJ");
      b.capacity_J = 1000 * capacity_kJ;
    }

    if (s.Has("line")) {
      if (!s.Has("name")) s.Fail("name", "missing: every barrier has a name");
      b.name = s.String("name", "");
      if (b.name.empty()) s.Fail("name", "the name is empty");
      b.vertices_m = PointList(s, s.Node("line"), s.Key("line"));
      barriers.push_back(b);
      origin.push_back(context.Where(s.Node("line")) + ": " + s.Key("line"));
    } else {
      if (s.Has("name"))
        s.Fail("name", "the lines of a file are named by its name_field attribute, not by name");
      const std::string path = context.Resolve(s.String("file", ""));
      std::vector<std::string> where;
      std::vector<std::vector<FeatureValue>> values;
      const std::vector<ensemble::EvaluationLine> lines = ReadLineFeatures(
          path, out.crs_wkt, s.String("name_field", "name"), s.Has("name_field"),
          context.Where(s.Node("file")) + ": " + s.Key("file"), &where, fields, &values);
      out.inputs.push_back(path);
      for (std::size_t l = 0; l < lines.size(); ++l) {
        Barrier from_file = b;
        ApplyFeatureAttributes(fields, values[l], where[l], &from_file);
        from_file.name =
            lines[l].name.empty() ? "barrier" + std::to_string(barriers.size() + 1) : lines[l].name;
        // The parts of a named multi-line (consecutive lines of one feature) are "<name> part <k>",
        // k from 1, so that names stay unique.
        std::size_t first = l, last = l;
        while (first > 0 && where[first - 1] == where[l]) --first;
        while (last + 1 < lines.size() && where[last + 1] == where[l]) ++last;
        if (!lines[l].name.empty() && last > first)
          from_file.name += " part " + std::to_string(l - first + 1);
        from_file.vertices_m = lines[l].vertices_m;
        barriers.push_back(from_file);
        origin.push_back(where[l]);
      }
    }
  }

  for (std::size_t k = 0; k < barriers.size(); ++k) {
    const Barrier& b = barriers[k];
    if (b.vertices_m.size() < 2)
      throw InputError(origin[k] + ": a barrier needs at least 2 points, it has " +
                       std::to_string(b.vertices_m.size()));
    for (const Eigen::Vector2d& v : b.vertices_m)
      if (!v.allFinite()) throw InputError(origin[k] + ": a point is not finite");
    if (!(b.length_m() > 0))
      throw InputError(origin[k] + ": the barrier has zero length (all its points are one point)");
    // A barrier stands on the terrain (its height is measured from it) and must be met where it
    // is drawn: all of it lies on the DEM. A barrier off it is almost always swapped coordinates
    // or another CRS.
    Eigen::Vector2d off;
    if (FirstPointOffDem(out.scene.terrain, b.vertices_m, &off)) {
      const GridGeometry& g = out.scene.terrain.heights().grid;
      throw InputError(origin[k] + ": the barrier '" + b.name +
                       "' is off the DEM or on nodata at (" + TenDigits(off.x()) + ", " +
                       TenDigits(off.y()) + "); the DEM covers x " + TenDigits(g.x0_m) + " .. " +
                       TenDigits(g.x_max_m()) + ", y " + TenDigits(g.y0_m) + " .. " +
                       TenDigits(g.y_max_m()) + ": every part of a barrier must lie on the DEM");
    }
    for (std::size_t j = 0; j < k; ++j)
      if (barriers[j].name == b.name)
        throw InputError(origin[k] + ": the name '" + b.name + "' is also that of " + origin[j] +
                         "; barrier names must be unique");
  }
}

}  // namespace talus::io::scene_tables
