#pragma once
// Fixtures for the point-cloud tests: synthetic clouds, files in a temporary directory, and mesh
// checks.

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "solver/polyhedron.hpp"
#include "tests/portable_random.hpp"

namespace talus::pointclouds::testing {

// A fresh directory under the system temp directory, removed with the fixture.
class TempDir {
 public:
  TempDir() {
    std::random_device rd;
    path_ = std::filesystem::temp_directory_path() / ("talus_pointclouds_" + std::to_string(rd()));
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  std::string File(const std::string& name) const { return (path_ / name).string(); }
  std::string Write(const std::string& name, const std::string& text) const {
    std::ofstream(File(name), std::ios::binary) << text;
    return File(name);
  }

 private:
  std::filesystem::path path_;
};

// Points as "x y z" lines with full double precision.
inline std::string XyzText(const std::vector<Eigen::Vector3d>& points) {
  std::string text;
  char line[128];
  for (const auto& p : points) {
    std::snprintf(line, sizeof line, "%.17g %.17g %.17g\n", p.x(), p.y(), p.z());
    text += line;
  }
  return text;
}

inline std::vector<Eigen::Vector3d> BoxCorners(double a, double b, double c) {
  std::vector<Eigen::Vector3d> p;
  for (int i = 0; i < 8; ++i)
    p.emplace_back((i & 1 ? 0.5 : -0.5) * a, (i & 2 ? 0.5 : -0.5) * b, (i & 4 ? 0.5 : -0.5) * c);
  return p;
}

// n points uniformly inside the box [-a/2, a/2] x [-b/2, b/2] x [-c/2, c/2] (shrunk by `margin`).
inline std::vector<Eigen::Vector3d> BoxInterior(double a, double b, double c, int n,
                                                std::mt19937_64& rng, double margin = 1e-3) {
  talus::testing::UniformReal<double> u(-0.5 + margin, 0.5 - margin);
  std::vector<Eigen::Vector3d> p;
  for (int i = 0; i < n; ++i) p.emplace_back(a * u(rng), b * u(rng), c * u(rng));
  return p;
}

// n points uniformly distributed on the unit sphere, scaled to semi-axes (ra, rb, rc).
inline std::vector<Eigen::Vector3d> EllipsoidSurface(double ra, double rb, double rc, int n,
                                                     std::mt19937_64& rng) {
  talus::testing::Normal g;
  std::vector<Eigen::Vector3d> p;
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d d = Eigen::Vector3d(g(rng), g(rng), g(rng)).normalized();
    p.emplace_back(ra * d.x(), rb * d.y(), rc * d.z());
  }
  return p;
}

// n points uniformly distributed on the surface of the box a x b x c centred at the origin
// (faces chosen with equal probability).
inline std::vector<Eigen::Vector3d> BoxSurface(double a, double b, double c, int n,
                                               std::mt19937_64& rng) {
  talus::testing::UniformReal<double> u(-0.5, 0.5);
  talus::testing::UniformInt face(0, 5);
  std::vector<Eigen::Vector3d> p;
  for (int i = 0; i < n; ++i) {
    Eigen::Vector3d q(u(rng), u(rng), u(rng));
    const int f = face(rng);
    q[f % 3] = f < 3 ? -0.5 : 0.5;
    p.push_back(q.cwiseProduct(Eigen::Vector3d(a, b, c)));
  }
  return p;
}

// `count` stray returns in random directions, min_m .. max_m from the origin.
inline std::vector<Eigen::Vector3d> FarOutliers(int count, double min_m, double max_m,
                                                std::mt19937_64& rng) {
  talus::testing::Normal g;
  talus::testing::UniformReal<double> r(min_m, max_m);
  std::vector<Eigen::Vector3d> p;
  for (int i = 0; i < count; ++i)
    p.push_back(Eigen::Vector3d(g(rng), g(rng), g(rng)).normalized() * r(rng));
  return p;
}

inline Eigen::Matrix3d RandomRotation(std::mt19937_64& rng) {
  talus::testing::Normal g;
  return Eigen::Quaterniond(g(rng), g(rng), g(rng), g(rng)).normalized().toRotationMatrix();
}

// A closed, consistently oriented mesh: every directed edge appears once and its reverse once.
inline ::testing::AssertionResult IsClosedAndOriented(const Polyhedron& poly) {
  std::map<std::pair<int, int>, int> directed;
  for (const auto& t : poly.triangles)
    for (int k = 0; k < 3; ++k) ++directed[{t[k], t[(k + 1) % 3]}];
  for (const auto& [edge, count] : directed) {
    if (count != 1)
      return ::testing::AssertionFailure()
             << "edge " << edge.first << "-" << edge.second << " used " << count << " times";
    if (!directed.count({edge.second, edge.first}))
      return ::testing::AssertionFailure()
             << "edge " << edge.first << "-" << edge.second << " has no twin";
  }
  const MassProperties mp = ComputeMassProperties(poly, 1.0);
  if (!(mp.volume_m3 > 0))
    return ::testing::AssertionFailure() << "volume " << mp.volume_m3 << " not positive";
  // Outward: every face plane has the centroid on its inner side.
  for (const auto& t : poly.triangles) {
    const Eigen::Vector3d& a = poly.vertices_m[t[0]];
    const Eigen::Vector3d n = (poly.vertices_m[t[1]] - a).cross(poly.vertices_m[t[2]] - a);
    if (n.dot(mp.centroid_m - a) > 1e-12 * n.norm())
      return ::testing::AssertionFailure() << "a triangle faces inward";
  }
  return ::testing::AssertionSuccess();
}

}  // namespace talus::pointclouds::testing
