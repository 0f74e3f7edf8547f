#pragma once
// The overrides of a scene's ensemble that talus simulate and talus validate both take: --rocks,
// --threads and --seed, with one help text and one check each.

#include <CLI/CLI.hpp>
#include <cstdint>
#include <optional>
#include <string>

#include "ensemble/release.hpp"

namespace talus::app {

struct EnsembleArgs {
  long rocks = 0;                     // per release (a run of a run table); 0: the scene's
  int threads = 0;                    // worker threads; 0: one per core
  std::optional<std::uint64_t> seed;  // none: the scene's

  // Sets --rocks and --seed in `release`. Throws InputError "--rocks N: <why>" when the release is
  // then invalid (the scene was valid: only too many rocks in all can break it).
  void ApplyTo(ensemble::ReleaseSpec& release) const;
};

// Adds --rocks ("Rocks per <rocks_per> (overrides the scene)"), --threads and --seed to `cmd`,
// parsed into *args, which must live as long as `cmd`'s parse.
void AddEnsembleOptions(CLI::App* cmd, EnsembleArgs* args, const std::string& rocks_per);

}  // namespace talus::app
