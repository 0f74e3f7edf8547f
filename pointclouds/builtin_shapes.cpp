#include "pointclouds/builtin_shapes.hpp"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>

#include "common/error.hpp"
#include "pointclouds/convex_hull.hpp"
#include "solver/random.hpp"
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

// A draw of rock points is kept when its rescaled hull holds at least this fraction of the
// ellipsoid's volume. A draw of 4 points falls below it with a chance of about 4 to 5 % (measured
// over 10^5 draws for roughness 0 to 0.5; the fraction does not depend on a, b, c), more points
// far less often, so that kMaxRockDraws failures in a row do not happen (0.05^100).
constexpr double kMinRockVolumeFraction = 0.01;
constexpr int kMaxRockDraws = 100;

// A direction uniform on the unit sphere: a point uniform in the cube [-1, 1]^3, kept when inside
// the ball (and not too close to the centre), normalised. Only +, *, / and sqrt in a fixed order
// (this file is compiled without FMA contraction): the same bits on every IEEE 754 platform,
// unlike cos and sin.
Eigen::Vector3d UniformDirection(RockRandom& random) {
  while (true) {
    const double x = 2 * random.Uniform() - 1;
    const double y = 2 * random.Uniform() - 1;
    const double z = 2 * random.Uniform() - 1;
    const double r2 = x * x + y * y + z * z;
    if (r2 > 1e-6 && r2 <= 1) {
      const double r = std::sqrt(r2);
      return Eigen::Vector3d(x / r, y / r, z / r);
    }
  }
}

// The built-in rock (see MakeBuiltinShape): hull of perturbed points on the ellipsoid, rescaled
// to the bounding box size_m, centred at the origin.
Polyhedron MakeRandomRock(const Eigen::Vector3d& size_m, int points, double roughness,
                          std::uint64_t seed) {
  RockRandom random(seed, kRockShapeStream);
  const Eigen::Vector3d semi_axes_m = size_m / 2;
  const double ellipsoid_m3 = std::numbers::pi / 6 * size_m.prod();
  std::vector<Eigen::Vector3d> cloud(static_cast<std::size_t>(points));
  for (int draw = 0; draw < kMaxRockDraws; ++draw) {
    for (auto& p : cloud) {
      const Eigen::Vector3d direction = UniformDirection(random);
      const double radius = 1 + roughness * (2 * random.Uniform() - 1);
      p = radius * direction.cwiseProduct(semi_axes_m);
    }
    Polyhedron hull;
    try {
      hull = ComputeConvexHull(cloud, "rock");
    } catch (const InputError&) {
      continue;  // coplanar within the hull's tolerance: draw again
    }
    Eigen::Vector3d lo = hull.vertices_m[0], hi = lo;
    for (const auto& v : hull.vertices_m) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
    const Eigen::Vector3d centre = (lo + hi) / 2, stretch = size_m.cwiseQuotient(hi - lo);
    for (auto& v : hull.vertices_m) v = (v - centre).cwiseProduct(stretch);
    if (ComputeMassProperties(hull, 1.0).volume_m3 >= kMinRockVolumeFraction * ellipsoid_m3)
      return hull;
  }
  std::ostringstream msg;
  msg << "rock: no solid hull in " << kMaxRockDraws << " draws of " << points
      << " points (shape_seed " << seed << ")";
  throw InputError(msg.str());
}

}  // namespace

const std::vector<std::string>& BuiltinShapeNames() {
  static const std::vector<std::string> names = {"box",  "ellipsoid", "icosphere", "cylinder",
                                                 "disk", "rock",      "eota111",   "eota221"};
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
  } else if ((name == "box" || name == "ellipsoid" || name == "rock") && n != 1 && n != 3) {
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
  } else if (points < 4 || points > 1000000) {
    msg << "points = " << points << " violates 4 <= points <= 10^6";
  } else if (!(roughness >= 0 && roughness <= 0.5)) {
    msg << "roughness = " << roughness << " violates 0 <= roughness <= 0.5";
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
  } else if (spec.name == "rock") {
    const double a = d[0], b = d.size() == 3 ? d[1] : a, c = d.size() == 3 ? d[2] : a;
    poly = MakeRandomRock(Eigen::Vector3d(a, b, c), spec.points, spec.roughness, spec.shape_seed);
    what << Dimensions({a, b, c}) << ", " << spec.points << " points, roughness " << spec.roughness
         << ", seed " << spec.shape_seed;
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
