#pragma once
// Hull simplification: the speed/accuracy knob of the rock shape (fewer vertices, fewer contact
// tests per step), with the volume and inertia it costs.

#include <string>

#include "solver/polyhedron.hpp"

namespace talus::pointclouds {

// What a simplification cost, measured against the hull it started from.
struct SimplifyReport {
  int vertices_before = 0;
  int vertices_after = 0;
  double volume_before_m3 = 0;
  double volume_after_m3 = 0;
  double volume_error = 0;    // (before - after) / before; >= 0, the simplified hull lies inside
  double inertia_error = 0;   // largest relative change of a principal moment at equal density
  double max_distance_m = 0;  // how far the farthest dropped vertex lies outside the result

  std::string BriefReport() const;
};

// Approximates a closed convex hull by the hull of at most max_vertices (>= 4) of its vertices,
// chosen greedily: a spanning tetrahedron first, then, one at a time, the vertex farthest
// outside the current hull. A hull with no more than max_vertices vertices comes back unchanged.
// Cost: about max_vertices^2 x (hull vertices) plane tests.
Polyhedron SimplifyHull(const Polyhedron& hull, int max_vertices, SimplifyReport* report = nullptr);

}  // namespace talus::pointclouds
