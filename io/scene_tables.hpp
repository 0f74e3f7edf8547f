#pragma once
// The tables of a scene file (docs/scenes.md), each read by its own function: the driver
// (LoadScene), [ground], [solver] and [output] in scene_file.cpp; [terrain] in scene_terrain.cpp;
// [rock] and [blocks] in scene_rock.cpp; [release], with run tables and single-impact tables, in
// scene_release.cpp; [evaluation_lines] in scene_evaluation_lines.cpp; [[barriers]] in
// scene_barriers.cpp; [forest] in scene_forest.cpp. Also the bounds of
// plausible input and the messages they share. Internal to io/: include it from .cpp files only
// (it brings in toml++).

#include <Eigen/Core>
#include <string>
#include <vector>

#include "common/format.hpp"
#include "io/scene_file.hpp"
#include "io/toml_section.hpp"

namespace talus::io::scene_tables {

inline constexpr auto kPositive = [](double v) { return v > 0; };

// Bounds of plausible input (docs/scenes.md): finite values beyond them are typos or wrong units,
// which would otherwise run and give wrong results.
inline constexpr double kMaxAbsHeight_m = 20000;  // DEM heights
inline constexpr double kMinDensity_kg_m3 = 100, kMaxDensity_kg_m3 = 30000;
inline constexpr double kMinVolume_m3 = 1e-9, kMaxVolume_m3 = 1e6;
inline constexpr double kMaxSpeed_m_s = 200, kMaxAngularSpeed_rad_s = 1000;
inline constexpr double kMaxReleaseHeight_m = 10000;

// "<v> is outside <lo> .. <hi> <unit>", or "" when lo <= v <= hi.
inline std::string OutsideBounds(double v, double lo, double hi, const std::string& unit) {
  if (v >= lo && v <= hi) return "";
  return TenDigits(v) + " is outside " + TenDigits(lo) + " .. " + TenDigits(hi) + " " + unit;
}

// Fails on `key` unless lo <= v <= hi.
inline void RequireWithin(const Section& s, const std::string& key, double v, double lo, double hi,
                          const std::string& unit) {
  if (const std::string why = OutsideBounds(v, lo, hi, unit); !why.empty()) s.Fail(key, why);
}

// "" when |v| <= max, else "|v| = <|v|> <unit> is more than <max> <unit>".
inline std::string TooFast(const Eigen::Vector3d& v, double max, const std::string& unit) {
  if (v.norm() <= max) return "";
  return "|v| = " + TenDigits(v.norm()) + " " + unit + " is more than " + TenDigits(max) + " " +
         unit;
}

// The list of [x, y] points at `node`; errors name `key`.
std::vector<Eigen::Vector2d> PointList(const Section& s, const toml::node* node,
                                       const std::string& key);

// [terrain]: the DEM or a plane, the default ground, the ground raster and ground polygons.
void LoadTerrain(const Context& context, const Section& s, SceneFile& out);
// [rock]: a point cloud file or a built-in shape, its density, volume or mass.
void LoadRock(const Context& context, const Section& s, SceneFile& out);
// [blocks]: the named rocks of a run table (nothing when `table` is null).
void LoadBlocks(const Context& context, const toml::table* table, SceneFile& out);
// [release]: where, how many and how rocks start.
void LoadRelease(const Context& context, const Section& s, SceneFile& out);
// [evaluation_lines]: the lines where crossing rocks are recorded (nothing without the table).
void LoadEvaluationLines(const Context& context, const Section& s, SceneFile& out);
// [[barriers]]: the barriers that act on the rocks, into out.scene.barriers (nothing when `node`,
// the scene's "barriers", is null).
void LoadBarriers(const Context& context, const toml::node* node, SceneFile& out);
// [forest]: explicit trees (a tree list and/or stands drawn from the seed), into
// out.scene.forest (nothing when the scene has no [forest], `given` false). After [release],
// whose seed is the forest's default.
void LoadForest(const Context& context, const Section& s, bool given, SceneFile& out);

}  // namespace talus::io::scene_tables
