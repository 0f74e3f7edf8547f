#include "pointclouds/rock_source.hpp"

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <sstream>
#include <utility>

#include "common/error.hpp"
#include "common/format.hpp"
#include "pointclouds/builtin_shapes.hpp"
#include "pointclouds/convex_hull.hpp"

namespace talus::pointclouds {
namespace {

BuiltinSpec ToBuiltinSpec(const RockSpec& spec) {
  BuiltinSpec builtin;
  builtin.name = spec.builtin;
  builtin.dimensions_m = spec.dimensions_m;
  builtin.subdivisions = spec.subdivisions;
  builtin.segments = spec.segments;
  builtin.points = spec.points;
  builtin.roughness = spec.roughness;
  builtin.shape_seed = spec.shape_seed;
  if (spec.volume_m3) builtin.volume_m3 = spec.volume_m3;
  if (spec.mass_kg) builtin.volume_m3 = *spec.mass_kg / spec.density_kg_m3;
  return builtin;
}

// The common tail of every rock: simplify, scale, mass properties in the principal frame,
// shape descriptors. `hull` is relative to `offset_m` in the input frame.
RockShape FinishRock(Polyhedron hull, const Eigen::Vector3d& offset_m, const RockSpec& spec,
                     RockReport& r) {
  if (spec.max_vertices > 0) {
    SimplifyReport simplify;
    hull = SimplifyHull(hull, spec.max_vertices, &simplify);
    r.simplify = simplify;
  }
  // Dimensions that fix the size keep it: the mass sets the density. Otherwise scale about the
  // centroid, which keeps the centroid where the shape put it.
  double density_kg_m3 = spec.density_kg_m3;
  std::optional<double> target_m3 = spec.volume_m3;
  if (spec.mass_kg && DimensionsFixSize(spec)) {
    density_kg_m3 = *spec.mass_kg / ComputeMassProperties(hull, 1.0).volume_m3;
    r.density_from_mass = true;
  } else if (spec.mass_kg) {
    target_m3 = *spec.mass_kg / spec.density_kg_m3;
  }
  if (target_m3) {
    const MassProperties mp = ComputeMassProperties(hull, density_kg_m3);
    r.scale = std::cbrt(*target_m3 / mp.volume_m3);
    for (auto& v : hull.vertices_m) v = mp.centroid_m + r.scale * (v - mp.centroid_m);
  }

  RockShape rock = MakeRockShape(hull, density_kg_m3);
  rock.centroid_input_m += offset_m;
  std::string why;
  if (!rock.IsValid(&why)) throw InputError(r.source + ": " + why);

  const MassProperties mp = ComputeMassProperties(hull, density_kg_m3);
  r.recentred_by_m = offset_m;
  r.hull_vertices = static_cast<int>(rock.vertices_m.size());
  r.hull_faces = static_cast<int>(hull.triangles.size());
  r.volume_m3 = rock.volume_m3;
  r.mass_kg = rock.mass_kg;
  r.density_kg_m3 = density_kg_m3;
  r.centroid_m = rock.centroid_input_m;
  r.inertia_kg_m2 = mp.inertia_kg_m2;
  r.principal_moments_kg_m2 = rock.inertia_kg_m2;
  r.principal_axes = rock.principal_to_input.toRotationMatrix();
  r.shape = DescribeShape(hull);
  r.hull = std::move(hull);
  return rock;
}

std::vector<double> Array(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

std::string Vec(const Eigen::Vector3d& v, const char* format = "%.6g") {
  std::string out = "(";
  for (int k = 0; k < 3; ++k) out += (k ? ", " : "") + FormatDouble(v[k], format);
  return out + ")";
}

}  // namespace

bool RockSpec::IsValid(std::string* why) const {
  std::ostringstream msg;
  std::string inner;
  if (file.empty() == builtin.empty())
    msg << (file.empty() ? "a rock needs a point cloud file or a built-in shape"
                         : "a rock takes a point cloud file or a built-in shape, not both");
  else if (!(density_kg_m3 > 0) || !std::isfinite(density_kg_m3))
    msg << "density_kg_m3 = " << density_kg_m3 << " violates 0 < density_kg_m3 < inf";
  else if (volume_m3 && mass_kg)
    msg << "give volume_m3 or mass_kg to scale the rock, not both";
  else if (volume_m3 && DimensionsFixSize(*this))
    msg << "volume_m3 = " << *volume_m3 << " contradicts the dimensions of the " << builtin
        << ", which fix its volume; give the dimensions or volume_m3, not both (mass_kg with "
           "the dimensions sets the density)";
  else if (volume_m3 && (!(*volume_m3 > 0) || !std::isfinite(*volume_m3)))
    msg << "volume_m3 = " << *volume_m3 << " violates 0 < volume_m3 < inf";
  else if (mass_kg && (!(*mass_kg > 0) || !std::isfinite(*mass_kg)))
    msg << "mass_kg = " << *mass_kg << " violates 0 < mass_kg < inf";
  else if (max_vertices != 0 && (max_vertices < 4 || max_vertices > 1000000))
    msg << "max_vertices = " << max_vertices
        << " violates max_vertices = 0 (off) or 4 <= max_vertices <= 10^6";
  else if (!clean.IsValid(&inner))
    msg << inner;
  else if (!builtin.empty() && !ToBuiltinSpec(*this).IsValid(&inner))
    msg << inner;
  if (msg.str().empty()) return true;
  if (why) *why = msg.str();
  return false;
}

bool DimensionsFixSize(const RockSpec& spec) {
  if (!spec.file.empty() || spec.dimensions_m.empty()) return false;
  for (const char* name : {"box", "ellipsoid", "icosphere", "cylinder", "disk", "rock"})
    if (spec.builtin == name) return true;
  return false;
}

std::uint64_t ShapeSeed(std::uint64_t base, std::uint64_t index) {
  std::uint64_t z = base + (index + 1) * 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

RockShape MakeRock(const RockSpec& spec, RockReport* report) {
  std::string why;
  if (!spec.IsValid(&why)) throw InputError((spec.file.empty() ? "rock" : spec.file) + ": " + why);
  if (!spec.file.empty()) return MakeRockFromPoints(ReadPointCloud(spec.file), spec, report);

  RockReport local;
  RockReport& r = report ? *report : local;
  r = RockReport{};
  Polyhedron shape = MakeBuiltinShape(ToBuiltinSpec(spec), &r.source);
  return FinishRock(std::move(shape), Eigen::Vector3d::Zero(), spec, r);
}

RockShape MakeRockFromPoints(PointCloud cloud, const RockSpec& spec, RockReport* report) {
  const std::string source = cloud.source.empty() ? "point cloud" : cloud.source;
  RockSpec checked = spec;
  checked.file = source;
  checked.builtin.clear();
  std::string why;
  if (!checked.IsValid(&why)) throw InputError(source + ": " + why);

  RockReport local;
  RockReport& r = report ? *report : local;
  r = RockReport{};
  r.source = source;
  r.points_read = cloud.points_m.size();
  r.clean = CleanPointCloud(spec.clean, &cloud);
  r.points_used = cloud.points_m.size();
  if (r.points_used < 4 && r.points_used < r.points_read) {
    std::ostringstream msg;
    msg << source << ": only " << r.points_used << " of " << r.points_read << " points are usable ("
        << r.clean.non_finite << " non-finite, " << r.clean.duplicates << " duplicates, "
        << r.clean.outliers << " outliers, " << r.clean.downsampled
        << " merged in voxels); a rock needs at least 4 points "
        << "that are not coplanar";
    throw InputError(msg.str());
  }
  Polyhedron hull = ComputeConvexHull(cloud.points_m, source);
  r.hull_check = CheckHull(cloud.points_m, ComputeMassProperties(hull, 1.0).volume_m3);
  if (const std::string warning = r.hull_check->Warning(source); !warning.empty())
    r.warnings.push_back(warning);
  return FinishRock(std::move(hull), cloud.offset_m, checked, r);
}

std::string RockReport::FullReport() const {
  std::ostringstream out;
  char line[256];
  out << "Rock: " << source << "\n";
  if (points_read > 0) {
    out << "  points: " << points_read << " read, " << points_used << " used (" << clean.non_finite
        << " non-finite, " << clean.duplicates << " duplicates, " << clean.outliers << " outliers, "
        << clean.downsampled << " merged in voxels dropped)\n";
    if (!recentred_by_m.isZero())
      out << "  recentred by " << Vec(recentred_by_m, "%.3f") << " m before any arithmetic\n";
  }
  for (const std::string& warning : warnings) out << "  WARNING: " << warning << "\n";
  out << "  hull: " << hull_vertices << " vertices, " << hull_faces << " triangles\n";
  if (simplify) out << "  simplified: " << simplify->BriefReport() << "\n";
  if (std::abs(scale - 1) > 1e-9) {
    std::snprintf(line, sizeof line, "  scaled by %.6g (linear) to the requested volume or mass\n",
                  scale);
    out << line;
  }
  std::snprintf(line, sizeof line, "  volume %.6g m^3, density %.6g kg/m^3%s, mass %.6g kg\n",
                volume_m3, density_kg_m3,
                density_from_mass ? " (the mass over the volume of the given dimensions)" : "",
                mass_kg);
  out << line;
  out << "  centroid " << Vec(centroid_m, "%.6f") << " m (input frame)\n";
  out << "  principal moments " << Vec(principal_moments_kg_m2) << " kg m^2 (ascending)\n";
  for (int k = 0; k < 3; ++k)
    out << "  principal axis " << k + 1 << " " << Vec(principal_axes.col(k), "%.6f")
        << " (input frame)\n";
  std::snprintf(line, sizeof line,
                "  dimensions a x b x c = %.4g x %.4g x %.4g m, b/a %.3f, c/b %.3f: %s (Zingg)\n",
                shape.dimensions_m.x(), shape.dimensions_m.y(), shape.dimensions_m.z(),
                shape.b_over_a, shape.c_over_b, ShapeClassName(shape.shape_class));
  out << line;
  std::snprintf(line, sizeof line, "  surface %.6g m^2, sphericity %.4f (Wadell)\n",
                shape.surface_area_m2, shape.sphericity);
  out << line;
  return out.str();
}

std::string RockReport::ToJson() const {
  nlohmann::ordered_json j;
  j["source"] = source;
  j["volume_m3"] = volume_m3;
  j["mass_kg"] = mass_kg;
  j["density_kg_m3"] = density_kg_m3;
  j["centroid_m"] = Array(centroid_m);
  j["principal_moments_kg_m2"] = Array(principal_moments_kg_m2);
  j["principal_axes"] = {Array(principal_axes.col(0)), Array(principal_axes.col(1)),
                         Array(principal_axes.col(2))};
  j["dimensions_m"] = Array(shape.dimensions_m);
  j["shape_class"] = ShapeClassName(shape.shape_class);
  j["b_over_a"] = shape.b_over_a;
  j["c_over_b"] = shape.c_over_b;
  j["sphericity"] = shape.sphericity;
  j["surface_area_m2"] = shape.surface_area_m2;
  j["hull_vertices"] = hull_vertices;
  j["hull_faces"] = hull_faces;
  j["points_read"] = points_read;
  j["points_used"] = points_used;
  j["scale"] = scale;
  j["density_from_mass"] = density_from_mass;
  j["recentred_by_m"] = Array(recentred_by_m);
  j["cleaning"] = {{"non_finite", clean.non_finite},
                   {"duplicates", clean.duplicates},
                   {"outliers", clean.outliers},
                   {"downsampled", clean.downsampled}};
  if (hull_check) {
    j["hull_check"] = {{"centre_m", Array(hull_check->centre_m + recentred_by_m)},
                       {"core_radius_m", hull_check->core_radius_m},
                       {"hull_volume_m3", hull_check->hull_volume_m3},
                       {"core_volume_m3", hull_check->core_volume_m3},
                       {"far_points", hull_check->far_points},
                       {"farthest_m", hull_check->farthest_m},
                       {"dominated", hull_check->Dominated()}};
  } else {
    j["hull_check"] = nullptr;
  }
  j["warnings"] = warnings;
  if (simplify) {
    j["simplification"] = {{"vertices_before", simplify->vertices_before},
                           {"vertices_after", simplify->vertices_after},
                           {"volume_error", simplify->volume_error},
                           {"inertia_error", simplify->inertia_error},
                           {"max_distance_m", simplify->max_distance_m}};
  } else {
    j["simplification"] = nullptr;
  }
  return j.dump(2);
}

}  // namespace talus::pointclouds
