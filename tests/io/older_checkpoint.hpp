#pragma once
// A calibration checkpoint as an older talus wrote it: an FNV-1a 64 checksum ("fnv1a64") and its
// calibration's FNV-1a hash as "path_hash". This talus refuses it, naming the file and saying what
// to do (tests/io/calibration_checkpoint_test.cpp, tests/app/calibrate_command_test.cpp).

namespace talus::testing {

inline constexpr const char* kOlderTalusCheckpoint =
    R"({"fnv1a64":"702b435a4ded976b","folds":0,"holdout":[],"path_hash":"44bda3d473cdc381",)"
    R"("stages":{"fit":[{"data":0.5,"failed_rocks":0,"feasible":true,"infeasible":"",)"
    R"("kind_scored":[4],"kind_scores":[0.5],"prior":0.0,"residuals":[0.25,-0.25],"rocks":8,)"
    R"("u":[0.5],"value":0.5,"values":[0.55],"wall_time_s":0.125}]}})"
    "\n";

}  // namespace talus::testing
