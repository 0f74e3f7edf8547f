#pragma once
// Point clouds of scanned rocks: reading (PCD, PLY, XYZ/CSV/TXT text, RAMMS-style .pts), cleaning
// (non-finite points, duplicates, statistical outliers, voxel downsampling) and writing a hull as
// PLY.

#include <Eigen/Core>
#include <cstddef>
#include <string>
#include <vector>

#include "solver/polyhedron.hpp"

namespace talus::pointclouds {

// The points of one scan, in metres. They are stored relative to offset_m, the centre of the
// bounding box of the finite points, subtracted in double precision as the file is read, so that
// georeferenced scans (coordinates of 10^6 m) keep their precision in all later arithmetic:
//   file coordinate = offset_m + points_m[i].
struct PointCloud {
  std::string source;                     // file path, for messages
  std::vector<Eigen::Vector3d> points_m;  // n, relative to offset_m; may hold non-finite points
  std::vector<int> source_lines;          // n, line of each point in a text file; empty otherwise
  Eigen::Vector3d offset_m = Eigen::Vector3d::Zero();
};

// Reads a point cloud; the format follows the extension (case-insensitive):
//   .pcd, .ply  PCL readers; the x, y, z fields of any numeric type, kept in double precision.
//   .xyz, .txt, .csv  one point per line, x y z first, separated by blanks, commas or semicolons
//               (on a line with a semicolon, commas do not separate: a decimal comma is an error,
//               not an extra coordinate); further columns (intensity, colour, normals) are
//               ignored, as are blank lines, comment lines (#, //) and one header line of column
//               names before the first point.
//   .pts  RAMMS-style point list: x y z per line as above; a line holding a single integer is a
//         point count (Leica PTS) and must match the number of points that follow it.
// Throws InputError naming the file (and line) for a missing or unreadable file, an unknown
// extension, a malformed line, or a file without points.
PointCloud ReadPointCloud(const std::string& path);

// Writes a closed triangle mesh as ASCII PLY (double-precision vertices, shifted by offset_m).
// Throws InputError when the file cannot be written.
void WritePolyhedronPly(const Polyhedron& poly, const Eigen::Vector3d& offset_m,
                        const std::string& path);

// What cleaning does to a scan before its hull is taken. The same fields are the keys of a
// scene's [rock] clean = { ... } and the options of `talus rock` (docs/scenes.md).
//
// Outlier removal is on by default because with these parameters it is safe: a point goes only
// when it is both a statistical outlier (PCL's rule, 6 standard deviations) and 5 times the
// scan's typical neighbour distance away from the others. The points of a clean scan of a rock,
// random or on a regular grid, corners and edges included, are within about twice the typical
// distance, so nothing is removed and the hull is the hull of all points; stray returns
// (vegetation, dust, range noise) well off the rock are removed. Tested on ellipsoid and box
// scans with 1 % and 5 % outliers (tests/pointclouds/point_cloud_test.cpp).
struct CleanOptions {
  bool drop_non_finite = true;  // false: a non-finite point is an error naming its line
  bool drop_duplicates = true;  // points with identical coordinates are kept once
  // Statistical outlier removal (PCL): a point whose mean distance to its outlier_neighbours
  // nearest neighbours exceeds the mean of that distance over the cloud by more than
  // outlier_std_ratio standard deviations, and (when outlier_spacing_ratio > 0) the median of
  // that distance over the cloud by the factor outlier_spacing_ratio, is dropped. Repeated until
  // a pass drops nothing, at most outlier_passes times: far outliers inflate the first pass's
  // standard deviation and hide nearer ones. 0 neighbours: off.
  int outlier_neighbours = 16;         // 0 (off) .. 1000
  double outlier_std_ratio = 6.0;      // > 0, dimensionless
  double outlier_spacing_ratio = 5.0;  // >= 0, dimensionless (0: the statistical rule alone)
  int outlier_passes = 10;             // 1 .. 100
  // Voxel downsampling: > 0 keeps, in each cube of this edge, the point nearest its centre
  // (points stay measured points, so the hull never grows). 0: off; else >= kMinVoxel_m, so that
  // voxel indices stay within 64-bit integers.
  double voxel_m = 0;
  static constexpr double kMinVoxel_m = 1e-6;

  // No cleaning beyond dropping non-finite points and duplicates (which never change a hull).
  static CleanOptions Off() {
    CleanOptions o;
    o.outlier_neighbours = 0;
    return o;
  }

  // False, with the field, value and violated bound in *why, when an option is out of range.
  bool IsValid(std::string* why) const;
};

// Counts of the points each cleaning stage removed.
struct CleanReport {
  std::size_t points_in = 0;
  std::size_t non_finite = 0;
  std::size_t duplicates = 0;
  std::size_t outliers = 0;
  std::size_t downsampled = 0;
  std::size_t points_out = 0;
};

// Cleans the cloud in place, in the order non-finite, duplicates, outliers, voxels.
// Throws InputError for a non-finite point when drop_non_finite is off.
CleanReport CleanPointCloud(const CleanOptions& options, PointCloud* cloud);

}  // namespace talus::pointclouds
