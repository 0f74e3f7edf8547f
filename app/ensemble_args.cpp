#include "app/ensemble_args.hpp"

#include <limits>

#include "app/commands.hpp"
#include "common/error.hpp"

namespace talus::app {

void EnsembleArgs::ApplyTo(ensemble::ReleaseSpec& release) const {
  if (rocks > 0) release.SetRocksPerRelease(rocks);
  if (seed) release.seed = *seed;
  if (std::string why; !release.IsValid(&why))
    throw InputError("--rocks " + std::to_string(rocks) + ": " + why);
}

void AddEnsembleOptions(CLI::App* cmd, EnsembleArgs* args, const std::string& rocks_per) {
  cmd->add_option("--rocks", args->rocks, "Rocks per " + rocks_per + " (overrides the scene)")
      ->check(IntegerRange(1, std::numeric_limits<long>::max()));
  cmd->add_option("--threads", args->threads, "Worker threads (default: all cores)")
      ->check(ThreadCount());
  // The scene's range: a seed given here can be written in the scene file and the other way round.
  cmd->add_option_function<std::uint64_t>(
         "--seed", [args](const std::uint64_t& seed) { args->seed = seed; },
         "Random seed (overrides the scene)")
      ->check(IntegerRange(0, std::numeric_limits<std::int64_t>::max()));
}

}  // namespace talus::app
