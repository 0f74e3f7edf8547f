#include "solver/scene.hpp"

namespace talus {

bool Scene::IsValid(std::string* why) const {
  std::string reason;
  auto fail = [&](const std::string& what) {
    if (why) *why = what + ": " + reason;
    return false;
  };
  if (!terrain.IsValid(&reason)) return fail("terrain");
  if (!ground.IsValid(&reason)) return fail("ground");
  if (!rock.IsValid(&reason)) return fail("rock");
  if (!options.IsValid(&reason)) return fail("solver");
  for (const Barrier& barrier : barriers)
    if (!barrier.IsValid(&reason)) return fail("barrier '" + barrier.name + "'");
  if (!forest.IsValid(&reason)) return fail("forest");
  if (!forest_drag.IsValid(&reason)) return fail("forest");
  if (terrain.default_ground() < 0 || terrain.default_ground() >= ground.size()) {
    reason =
        "default ground index " + std::to_string(terrain.default_ground()) + " is not in the table";
    return fail("terrain");
  }
  if (terrain.has_ground_grid()) {
    for (auto index : terrain.ground_grid().index) {
      if (index != GroundGrid::kNoGround && index >= ground.size()) {
        reason =
            "ground grid refers to category index " + std::to_string(index) + " not in the table";
        return fail("terrain");
      }
    }
  }
  return true;
}

}  // namespace talus
