#pragma once
// summary.json (docs/scenes.md): inputs' hash, version, counts by ending, wall time,
// trajectories per second, and what the run was.

#include <string>
#include <vector>

#include "ensemble/runner.hpp"
#include "ensemble/self_check.hpp"
#include "io/barriers_csv.hpp"
#include "io/evaluation_lines_csv.hpp"
#include "io/scene_file.hpp"
#include "io/tree_impacts_csv.hpp"

namespace talus::io {

// The summary as JSON text; `outputs` lists the files written next to it. `evaluation_lines`, the
// per-line summary of a scene with evaluation lines, goes under "evaluation_lines"; a self-check's
// report (talus simulate --self-check) under "self_check"; `barriers`, the per-barrier summary of
// a scene with barriers, under "barriers" (and the ending "barrier" joins "ends"); a scene with a
// forest lists its trees and stands under "forest", with `trees`, the summary of its
// tree_impacts.csv, when given.
std::string SummaryJson(const SceneFile& scene, const ensemble::EnsembleReport& report,
                        const std::string& version, const std::vector<std::string>& outputs,
                        const std::vector<EvaluationLineSummary>& evaluation_lines = {},
                        const ensemble::SelfCheckReport* self_check = nullptr,
                        const std::vector<BarrierSummary>& barriers = {},
                        const TreeImpactSummary* trees = nullptr,
                        const std::vector<ensemble::RasterLayer>& rasters = {});

// The ground table as used, as summary.json's "ground" holds it, on one line (compact JSON).
std::string GroundTableJson(const GroundTable& table);

}  // namespace talus::io
