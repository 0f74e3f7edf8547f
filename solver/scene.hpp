#pragma once
// The immutable scene a simulation reads: terrain, ground table, rock, solver options and the
// barriers and the trees that act on the rocks.

#include <string>
#include <vector>

#include "solver/barriers.hpp"
#include "solver/forest.hpp"
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
  // Barriers the rocks meet (solver/barriers.hpp); none: no barrier work at all.
  std::vector<Barrier> barriers;
  // Trees whose stems the rocks hit (solver/forest.hpp); none: no forest work at all.
  Forest forest;
  // The forest as a drag layer (solver/forest.hpp, ForestDrag); empty: no forest drag work.
  ForestDrag forest_drag;

  // Checks every part (each barrier too) and that the terrain's ground indices exist in the table.
  bool IsValid(std::string* why) const;
};

}  // namespace talus
