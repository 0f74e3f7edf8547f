#pragma once
// Point clouds and built-in shapes to rocks: the one entry point that scene files and the
// `talus rock` verbs use. Reads and cleans the points, takes the convex hull, optionally
// simplifies it and scales it to a volume or mass, and builds the solver's RockShape, with a
// report of everything on the way.

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "pointclouds/hull_check.hpp"
#include "pointclouds/hull_simplify.hpp"
#include "pointclouds/point_cloud.hpp"
#include "pointclouds/shape_descriptors.hpp"
#include "solver/polyhedron.hpp"

namespace talus::pointclouds {

// Where a rock comes from: a point cloud file or a built-in shape, with its density and knobs.
// The input frame is the file's axes, or the built-in's a, b, c along x, y, z.
//
// Size and mass: a built-in whose dimensions fix its size (box, ellipsoid, icosphere, cylinder,
// disk or rock with dimensions_m given; see DimensionsFixSize) keeps them. mass_kg then sets the
// density (mass_kg / volume of the shape; density_kg_m3 is not used), and volume_m3 is an error
// (the dimensions fix the volume). EOTA blocks of given dimensions keep their bounding box and
// take the bevel that gives the volume (volume_m3, or mass_kg / density_kg_m3). Point clouds and
// built-ins without dimensions are scaled about their centroid to volume_m3 or to
// mass_kg / density_kg_m3.
struct RockSpec {
  std::string file;     // point cloud path (PCD, PLY, XYZ/CSV/TXT, PTS); empty for a built-in
  std::string builtin;  // "box", "ellipsoid", "icosphere", "cylinder", "disk", "rock", "eota111",
                        // "eota221"
  // Built-in dimensions (box a, b, c; ellipsoid and rock a, b, c; icosphere diameter; cylinder
  // diameter, height; EOTA bounding box or none), as BuiltinSpec documents.
  std::vector<double> dimensions_m;
  double density_kg_m3 = 2700;
  std::optional<double> volume_m3, mass_kg;  // at most one; see above
  int max_vertices = 0;                      // 0: no simplification; else >= 4
  CleanOptions clean;                        // point clouds only
  int subdivisions = 2;                      // built-in ellipsoid and icosphere
  int segments = 24;                         // built-in cylinder and disk
  // Built-in rock: random points on the ellipsoid (4 .. 10^6), their radial perturbation
  // (dimensionless, 0 .. 0.5) and the seed of their stream, as BuiltinSpec documents.
  int points = 32;
  double roughness = 0.15;
  std::uint64_t shape_seed = 0;

  // False, with the field, value and reason in *why, when the spec cannot make a rock.
  bool IsValid(std::string* why) const;
};

// Everything `talus rock info` prints. Vectors and frames are in the input frame (file
// coordinates, not recentred) unless the name says otherwise.
struct RockReport {
  std::string source;  // the file, or what the built-in is
  // Points (zero for built-ins).
  std::size_t points_read = 0;
  std::size_t points_used = 0;  // after cleaning
  CleanReport clean;
  // Of a point cloud: whether a few of the used points dominate the hull, and the warning then.
  std::optional<HullCheck> hull_check;
  std::vector<std::string> warnings;
  Eigen::Vector3d recentred_by_m = Eigen::Vector3d::Zero();  // subtracted before any arithmetic
  // The hull the rock uses (after simplification).
  int hull_vertices = 0;
  int hull_faces = 0;  // triangles
  std::optional<SimplifyReport> simplify;
  double scale = 1;  // linear factor applied to reach volume_m3 or mass_kg
  // Mass properties.
  double volume_m3 = 0;
  double mass_kg = 0;
  double density_kg_m3 = 0;        // the density used
  bool density_from_mass = false;  // mass_kg / volume (dimensions that fix the size), see RockSpec
  Eigen::Vector3d centroid_m = Eigen::Vector3d::Zero();
  Eigen::Matrix3d inertia_kg_m2 = Eigen::Matrix3d::Zero();  // about the centroid, input axes
  Eigen::Vector3d principal_moments_kg_m2 = Eigen::Vector3d::Zero();  // ascending
  // Columns: unit principal axes in the input frame, in the order of the moments; right-handed
  // (the rotation RockShape::principal_to_input).
  Eigen::Matrix3d principal_axes = Eigen::Matrix3d::Identity();
  ShapeDescriptors shape;
  // The rock's hull, relative to recentred_by_m (input coordinate = recentred_by_m + vertex).
  Polyhedron hull;

  // A few lines for people.
  std::string FullReport() const;
  // The stable JSON interface for scripts: volume_m3, mass_kg, density_kg_m3, centroid_m [3],
  // principal_moments_kg_m2 [3, ascending], principal_axes [3 unit vectors], dimensions_m
  // [a >= b >= c], shape_class, sphericity, hull_vertices, hull_faces, points_read, points_used,
  // and more (source, b_over_a, c_over_b, surface_area_m2, scale, density_from_mass,
  // recentred_by_m, cleaning, simplification, hull_check, warnings). Keys are only ever added.
  std::string ToJson() const;
};

// True when the spec is a built-in whose dimensions fix its size: box, ellipsoid, icosphere,
// cylinder, disk or rock with dimensions_m given. Then mass_kg sets the density and volume_m3 is
// rejected (see RockSpec).
bool DimensionsFixSize(const RockSpec& spec);

// The shape_seed of rock `index` of a run whose rocks each get their own built-in rock shape: the
// output number index + 1 of a SplitMix64 generator (Steele, Lea & Flood 2014) seeded with
// `base`, i.e. the SplitMix64 finaliser of base + (index + 1) * 0x9e3779b97f4a7c15 (mod 2^64).
// Pure and portable: rock k's shape depends on (base, k) only. E.g. ShapeSeed(0, 0) =
// 0xe220a8397b1dcdaf, the first output of SplitMix64 seeded with 0.
std::uint64_t ShapeSeed(std::uint64_t base, std::uint64_t index);

// Builds the rock a spec describes; fills *report when given. Throws InputError (naming the file
// and, where it applies, the line) for a bad spec, an unreadable or unusable point cloud, or a
// shape the solver cannot use.
RockShape MakeRock(const RockSpec& spec, RockReport* report = nullptr);

// The same from points already read (spec.file is ignored; the cloud's source names it).
RockShape MakeRockFromPoints(PointCloud cloud, const RockSpec& spec, RockReport* report = nullptr);

}  // namespace talus::pointclouds
