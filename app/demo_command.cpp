// talus demo: one EOTA221 block down the 40 degree benchmark ramp.

#include <cstdint>
#include <cstdio>
#include <iostream>
#include <limits>
#include <memory>

#include "app/commands.hpp"
#include "app/console.hpp"
#include "scenes/scenes.hpp"
#include "solver/simulate.hpp"

namespace talus::app {
namespace {

int RunDemo(std::uint64_t seed) {
  const Scene scene = scenes::Ramp40();
  std::string why;
  if (!scene.IsValid(&why)) {
    std::cerr << "talus demo: " << why << "\n";
    return kExitRunFailed;
  }
  const RockState start = scenes::Ramp40Release(scene, seed, 0);
  SimulationWorkspace workspace;
  const RockResult result = SimulateRock(scene, start, workspace);
  const auto& end = result.final_state.position_m;
  Say("Demo: EOTA221 block (%.0f kg) released 1 m above a 40 deg ramp (medium_hard ground), seed "
      "%llu\n",
      scene.rock.mass_kg, static_cast<unsigned long long>(seed));
  Say("  %s\n", result.BriefReport().c_str());
  Say("  end position (%.2f, %.2f, %.2f) m, runout %.1f m from release\n", end.x(), end.y(),
      end.z(), result.runout_m);
  return result.end == EndReason::kFailed ? kExitRunFailed : kExitOk;
}

}  // namespace

Runner AddDemoCommand(CLI::App& app) {
  auto seed = std::make_shared<std::uint64_t>(1);
  CLI::App* demo =
      app.add_subcommand("demo", "Run one EOTA221 block down the 40 degree benchmark ramp");
  demo->add_option("--seed", *seed, "Random seed of the release orientation")
      ->check(IntegerRange(0, std::numeric_limits<std::int64_t>::max()));
  return [demo, seed]() { return *demo ? RunDemo(*seed) : -1; };
}

}  // namespace talus::app
