#include "pointclouds/builtin_shapes.hpp"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <sstream>

#include "common/error.hpp"
#include "solver/shapes.hpp"

namespace talus::pointclouds {
namespace {

// Standard EOTA blocks of 1 m^3 (ETAG 027 / EAD 340059).
struct EotaStandard {
  double a_m, b_m, c_m;
};
constexpr EotaStandard kEota111{1.122, 1.122, 1.122};
constexpr EotaStandard kEota221{1.414, 1.414, 0.707};

bool IsEota(const std::string& name) { return name == "eota111" || name == "eota221"; }

std::string Dimensions(const std::vector<double>& d) {
  std::ostringstream out;
  for (std::size_t i = 0; i < d.size(); ++i) out << (i ? " x " : "") << d[i];
  out << " m";
  return out.str();
}

}  // namespace

const std::vector<std::string>& BuiltinShapeNames() {
  static const std::vector<std::string> names = {"box",  "ellipsoid", "icosphere", "cylinder",
                                                 "disk", "eota111",   "eota221"};
  return names;
}

bool BuiltinSpec::IsValid(std::string* why) const {
  std::ostringstream msg;
  const auto& names = BuiltinShapeNames();
  const std::size_t n = dimensions_m.size();
  const bool all_positive = std::all_of(dimensions_m.begin(), dimensions_m.end(),
                                        [](double d) { return d > 0 && std::isfinite(d); });
  if (std::find(names.begin(), names.end(), name) == names.end()) {
    msg << "unknown built-in shape '" << name << "'; expected one of";
    for (const auto& known : names) msg << " " << known;
  } else if (!all_positive) {
    msg << name << " dimensions (" << Dimensions(dimensions_m) << ") must be positive and finite";
  } else if ((name == "box" || name == "ellipsoid") && n != 1 && n != 3) {
    msg << name << " takes 1 or 3 dimensions (a, b, c in m), got " << n;
  } else if (name == "icosphere" && n > 1) {
    msg << "icosphere takes 1 dimension (diameter in m), got " << n;
  } else if ((name == "cylinder" || name == "disk") && n != 2) {
    msg << name << " takes 2 dimensions (diameter, height in m), got " << n;
  } else if (IsEota(name) && n != 0 && n != 1 && n != 3) {
    msg << name << " takes 0, 1 or 3 dimensions (bounding box in m), got " << n;
  } else if (subdivisions < 0 || subdivisions > 6) {
    msg << "subdivisions = " << subdivisions << " violates 0 <= subdivisions <= 6";
  } else if (segments < 3 || segments > 4096) {
    msg << "segments = " << segments << " violates 3 <= segments <= 4096";
  } else if (volume_m3 && !(*volume_m3 > 0 && std::isfinite(*volume_m3))) {
    msg << "volume_m3 = " << *volume_m3 << " must be positive and finite";
  }
  if (msg.str().empty()) return true;
  if (why) *why = msg.str();
  return false;
}

Polyhedron MakeBuiltinShape(const BuiltinSpec& spec, std::string* description) {
  std::string why;
  if (!spec.IsValid(&why)) throw InputError(why);
  const auto& d = spec.dimensions_m;
  std::ostringstream what;
  what << spec.name << " ";
  Polyhedron poly;
  if (spec.name == "box") {
    const double a = d[0], b = d.size() == 3 ? d[1] : a, c = d.size() == 3 ? d[2] : a;
    poly = MakeBox(a, b, c);
    what << Dimensions({a, b, c});
  } else if (spec.name == "ellipsoid") {
    const double a = d[0], b = d.size() == 3 ? d[1] : a, c = d.size() == 3 ? d[2] : a;
    poly = MakeEllipsoid(a, b, c, spec.subdivisions);
    what << Dimensions({a, b, c}) << ", " << poly.vertices_m.size() << " vertices";
  } else if (spec.name == "icosphere") {
    const double diameter = d.empty() ? 1.0 : d[0];
    poly = MakeIcosphere(diameter / 2, spec.subdivisions);
    what << "diameter " << diameter << " m, " << poly.vertices_m.size() << " vertices";
  } else if (spec.name == "cylinder" || spec.name == "disk") {
    poly = MakeCylinder(d[0] / 2, d[1], spec.segments);
    what << "diameter " << d[0] << " m, height " << d[1] << " m, " << spec.segments << " segments";
  } else {
    // EOTA blocks: the standard 1 m^3 block fixes the proportions and the bevel-to-side ratio.
    const EotaStandard standard = spec.name == "eota111" ? kEota111 : kEota221;
    const Eigen::Vector3d standard_m(standard.a_m, standard.b_m, standard.c_m);
    Eigen::Vector3d box_m = standard_m;
    if (d.empty()) box_m *= std::cbrt(spec.volume_m3.value_or(1.0));
    if (d.size() == 1) box_m *= d[0] / standard.a_m;
    if (d.size() == 3) box_m = Eigen::Vector3d(d[0], d[1], d[2]);
    double bevel = 0;
    if (d.empty() || spec.volume_m3) {
      bevel = BevelForVolume(box_m.x(), box_m.y(), box_m.z(), spec.volume_m3.value_or(1.0));
    } else {
      const double standard_bevel = BevelForVolume(standard.a_m, standard.b_m, standard.c_m, 1.0);
      bevel = standard_bevel / standard_m.minCoeff() * box_m.minCoeff();
    }
    if (bevel < 0) {
      std::ostringstream msg;
      msg << spec.name << ": no bevel gives a volume of " << *spec.volume_m3 << " m^3 to a "
          << Dimensions({box_m.x(), box_m.y(), box_m.z()}) << " block (at most " << box_m.prod()
          << " m^3)";
      throw InputError(msg.str());
    }
    poly = MakeBevelledBox(box_m.x(), box_m.y(), box_m.z(), bevel);
    what << Dimensions({box_m.x(), box_m.y(), box_m.z()}) << ", bevel " << bevel << " m";
  }
  if (description) *description = what.str();
  return poly;
}

}  // namespace talus::pointclouds
