#pragma once
// The [rock] table of a scene, and the rock shape it describes (built by the pointclouds module:
// point cloud files and built-in shapes alike).

#include <optional>
#include <string>
#include <vector>

#include "solver/polyhedron.hpp"

namespace talus::io {

struct RockInput {
  std::string file;                   // point cloud file (absolute path), or empty for a built-in
  std::string builtin;                // "box", "ellipsoid", "icosphere", "cylinder", "eota111", "eota221"
  std::vector<double> dimensions_m;   // as pointclouds::BuiltinSpec documents
  double density_kg_m3 = 2700;
  std::optional<double> volume_m3;    // scale the shape to this volume ...
  std::optional<double> mass_kg;      // ... or to this mass at the density
  int max_vertices = 0;               // hull simplification; 0: none
  std::string description;            // for reports, e.g. "box 1 x 1 x 1 m"
};

// Builds the solver's rock through pointclouds::MakeRock; *hull_report (if given) receives its
// one-line description. Throws InputError.
RockShape BuildRock(const RockInput& input, std::string* hull_report = nullptr);

}  // namespace talus::io
