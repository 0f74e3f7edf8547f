#pragma once
// The immutable scene a simulation reads: terrain, ground table, rock and solver options.

#include <string>

#include "solver/ground.hpp"
#include "solver/options.hpp"
#include "solver/polyhedron.hpp"
#include "solver/terrain.hpp"

namespace talus {

struct Scene {
  Terrain terrain;
  GroundTable ground = GroundTable::BuiltIn();
  RockShape rock;
  SolverOptions options;

  // Checks every part and that the terrain's ground indices exist in the table.
  bool IsValid(std::string* why) const;
};

}  // namespace talus
