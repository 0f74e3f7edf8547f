#pragma once
// Field observations of an event and the readers of their tables. Each observation belongs to a
// run (an experiment's release, a documented event's block) or to the whole scene, and names the
// quantity whose simulated counterpart it is scored against (validation.hpp).

#include <Eigen/Core>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "common/csv_table.hpp"
#include "solver/terrain.hpp"

namespace talus::fieldobs {

// A scalar quantity observed in the field, and how each simulated rock of its run gives it.
enum class Quantity {
  kRunout,                 // m: horizontal distance release -> end (RockResult::runout_m)
  kImpactSpeedOut,         // m/s: speed leaving the run's first contact episode
  kImpactEnergyRatio,      // translational kinetic energy after / before the first contact episode
  kImpactAngularSpeedOut,  // rad/s: angular speed leaving the first contact episode
  kImpactDuration,         // s: duration of the first contact episode
  kScarLength,             // m: longest scar of the run's first loaded contact episode
  kImpactScarDepth,        // m: deepest penetration of the first contact episode (soil; 0 hard)
  // Over an observed trajectory segment: from the run's start for the segment's duration.
  kSegmentMaxSpeed,          // m/s: largest speed of the centre of mass
  kSegmentMeanAngularSpeed,  // rad/s: mean angular speed
  kSegmentMaxJumpHeight,     // m: largest height of the centre of mass above the terrain (normal)
  // At a zone (ObservationSet::zones): a line's first crossing, or the largest value inside a
  // polygon; only rocks that reached the zone give a value, except kZonePassed (0 or 1, every
  // rock).
  kZoneSpeed,         // m/s
  kZoneAngularSpeed,  // rad/s
  kZoneJumpHeight,    // m: centre of mass above the terrain along its normal
  kZonePassed,        // 1: the rock crossed the line or entered the polygon, else 0
};

// A place where something was observed: an evaluation line (a barrier's line, a survey profile)
// or a polygon, in map coordinates.
struct Zone {
  std::string id;
  bool polygon = false;
  std::vector<Eigen::Vector2d> points;  // the line's vertices, or the polygon's ring
};
const char* ToString(Quantity quantity);  // "runout", "impact_speed_out", ...
const char* UnitOf(Quantity quantity);    // "m", "m/s", "1", "rad/s", "s"

struct ScalarObservation {
  Quantity quantity = Quantity::kRunout;
  std::string run;  // run id; empty: the whole scene's rocks
  double value = 0;
  std::string where;    // "file:line", for reports
  double window_s = 0;  // segment quantities: the time from the run's start they cover
  int zone = -1;        // zone quantities: index into ObservationSet::zones
};

// A surveyed rest position (map coordinates, m), optionally with its uncertainty radius.
struct DepositObservation {
  std::string run;  // run id; empty: the whole scene's rocks
  Eigen::Vector2d xy_m = Eigen::Vector2d::Zero();
  std::optional<double> radius_m;
  std::string where;
};

struct ObservationSet {
  std::vector<ScalarObservation> scalars;
  std::vector<DepositObservation> deposits;
  std::vector<Zone> zones;
  std::size_t size() const { return scalars.size() + deposits.size(); }
};

// Which columns a table's values come from; defaults are the documented column names
// (docs/validation.md), so that tables in that format need no configuration.
struct TableColumns {
  std::string run = "trajectory_id";  // absent column: every row is about the whole scene
  // Impacts with a table of trajectory samples (ReadImpacts' `next_samples`): the column naming
  // the segment (run) that begins after the impact.
  std::string next_run = "next_segment_id";
};

// Reads the rows of `table` as observations of each kind. Throws InputError naming the file, line
// and column for a missing column or a bad value. Rows whose value cell is empty are skipped.
//  - runout: `observed_runout_m`
//  - deposits: `x_m`, `y_m`, optional `radius_m` (uncertainty, m)
//  - impacts: incoming and outgoing velocity as `incoming_vx_mps` .. `outgoing_vz_mps` (or the
//    speeds `incoming_speed_mps`, `outgoing_speed_mps`), optional `omega_out_radps`,
//    `duration_s`; each gives impact_speed_out, impact_energy_ratio and, where present, angular
//    speed and duration
//  - scars: `scar_length_m`
void ReadRunouts(const CsvTable& table, const TableColumns& columns, ObservationSet& out);
void ReadDeposits(const CsvTable& table, const TableColumns& columns, ObservationSet& out);
void ReadImpacts(const CsvTable& table, const TableColumns& columns, ObservationSet& out);
void ReadScars(const CsvTable& table, const TableColumns& columns, ObservationSet& out);
// Impacts as above. With `next_samples`, a table of observed trajectory samples (flight segments:
// the run column, `time_s`, `omega_x_radps`, `omega_y_radps`, `omega_z_radps` in rad/s, any
// frame), a row without `omega_out_radps` takes as its angular speed after the impact the |omega|
// of the first sample (smallest time_s) of the segment named in its `columns.next_run` column:
// the rotation the block left the ground with. A segment whose first sample has no angular
// velocity (empty or NaN cells) gives no angular observation; a segment the samples do not hold
// is an error naming the impact table's line and column.
void ReadImpacts(const CsvTable& table, const TableColumns& columns, ObservationSet& out,
                 const CsvTable* next_samples);

// The |omega| (rad/s) of the first sample (smallest time_s, the earlier line on a tie) of every
// run of a trajectory-sample table (columns as for ReadImpacts' `next_samples`); nullopt for a
// run whose first sample has no angular velocity. Throws InputError for a missing column or a
// bad number.
std::vector<std::pair<std::string, std::optional<double>>> FirstAngularSpeeds(
    const CsvTable& samples, const TableColumns& columns);

// Zone observations: `zone_id` (one of out.zones), `quantity` (speed_mps, angular_speed_radps,
// jump_height_m or passed) and `value` (passed: 0 or 1, e.g. one row per observed block).
void ReadZoneObservations(const CsvTable& table, const TableColumns& columns, ObservationSet& out);

// Sampled trajectory segments (`time_s`, `x_m`, `y_m`, `z_m` of the centre of mass; `speed_mps` or
// `vx_mps`, `vy_mps`, `vz_mps`; optional `omega_x_radps`, `omega_y_radps`, `omega_z_radps`), rows
// grouped by run, each run's samples from its start. Each run gives its segment's largest speed,
// mean angular speed (when given) and largest jump height over `terrain` (centre of mass above the
// terrain along its normal, samples over the DEM only), with the segment's duration as the window.
// A run needs at least 2 samples, in increasing time. A run any of whose samples has no angular
// velocity (empty or NaN cells) gives no angular-speed observation: its mean would not cover the
// segment.
void ReadTrajectories(const CsvTable& table, const TableColumns& columns, const Terrain& terrain,
                      ObservationSet& out);

}  // namespace talus::fieldobs
