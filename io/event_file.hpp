#pragma once
// Event files (EVENT.toml, docs/validation.md): a scene and the field observations of what
// happened there. Loading validates everything -- the scene, every observation table, and that
// every observation's run exists in the scene -- before any rock runs; errors name the file, line
// and key or column.

#include <string>
#include <vector>

#include "fieldobs/observations.hpp"
#include "io/scene_file.hpp"

namespace talus::io {

struct EventFile {
  std::string path;
  SceneFile scene;
  fieldobs::ObservationSet observations;
  // Which of the observation kinds were given: impacts and scars need contact episodes.
  bool needs_episodes = false;
  // The reference parameter set skill scores compare with: "table1" (the seed paper's Table 1
  // values of the built-in categories the scene uses, user categories unchanged) or "none".
  std::string reference = "table1";
  // Observed values the tables hold that have no simulated counterpart (e.g. scar depths), one
  // line each naming the file and column and saying why: printed and listed in scores.json.
  std::vector<std::string> not_scored;
  std::vector<std::string> inputs;  // the event file, the scene's inputs, the observation tables
  std::string inputs_hash;          // SHA-256 of the event file, the tables and the scene's hash
};

// Throws InputError "<file>:<line>: <key>: <reason>" (or the table's file:line: column).
// Keys: `scene`, `reference`, and [[observations]] tables with `kind` (runout, deposits, impacts,
// scars, trajectories, zones, single_impacts), `file`, optional `run_column` (default
// trajectory_id) and, for impacts only, `omega_from`: a table of observed trajectory samples from
// which each impact's angular speed after the impact is taken (fieldobs::ReadImpacts'
// `next_samples`). single_impacts (fieldobs::ReadSingleImpactOutcomes) take `id_column`,
// `energy_ratio_column`, `speed_out_column` and `scar_depth_column` instead of `run_column`; their
// runs are the scene's [release] single_impacts.
EventFile LoadEvent(const std::string& path);

// The scene's ground table with the Table 1 values for the built-in categories (user categories
// kept), and whether it differs from the scene's.
GroundTable ReferenceGround(const GroundTable& scene_ground, bool* differs);

}  // namespace talus::io
