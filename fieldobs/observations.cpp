#include "fieldobs/observations.hpp"

#include <algorithm>
#include <cmath>
#include <unordered_map>

#include "common/error.hpp"

namespace talus::fieldobs {

const char* ToString(Quantity quantity) {
  switch (quantity) {
    case Quantity::kRunout:
      return "runout";
    case Quantity::kImpactSpeedOut:
      return "impact_speed_out";
    case Quantity::kImpactEnergyRatio:
      return "impact_energy_ratio";
    case Quantity::kImpactAngularSpeedOut:
      return "impact_angular_speed_out";
    case Quantity::kImpactDuration:
      return "impact_duration";
    case Quantity::kScarLength:
      return "scar_length";
    case Quantity::kImpactScarDepth:
      return "impact_scar_depth";
    case Quantity::kSegmentMaxSpeed:
      return "segment_max_speed";
    case Quantity::kSegmentMeanAngularSpeed:
      return "segment_mean_angular_speed";
    case Quantity::kSegmentMaxJumpHeight:
      return "segment_max_jump_height";
    case Quantity::kZoneSpeed:
      return "zone_speed";
    case Quantity::kZoneAngularSpeed:
      return "zone_angular_speed";
    case Quantity::kZoneJumpHeight:
      return "zone_jump_height";
    case Quantity::kZonePassed:
      return "zone_passed";
  }
  return "unknown";
}

const char* UnitOf(Quantity quantity) {
  switch (quantity) {
    case Quantity::kRunout:
    case Quantity::kScarLength:
    case Quantity::kImpactScarDepth:
    case Quantity::kSegmentMaxJumpHeight:
    case Quantity::kZoneJumpHeight:
      return "m";
    case Quantity::kZoneSpeed:
      return "m/s";
    case Quantity::kZoneAngularSpeed:
      return "rad/s";
    case Quantity::kZonePassed:
      return "1";
    case Quantity::kImpactSpeedOut:
    case Quantity::kSegmentMaxSpeed:
      return "m/s";
    case Quantity::kSegmentMeanAngularSpeed:
      return "rad/s";
    case Quantity::kImpactEnergyRatio:
      return "1";
    case Quantity::kImpactAngularSpeedOut:
      return "rad/s";
    case Quantity::kImpactDuration:
      return "s";
  }
  return "";
}

namespace {

std::string RunOf(const CsvTable& t, const TableColumns& c, int row) {
  if (!t.Has(c.run)) return "";
  std::string run = t.Text(row, c.run);
  if (run.empty()) throw InputError(t.Where(row, c.run) + ": empty run id");
  return run;
}

std::string Where(const CsvTable& t, int row) {
  return t.path() + ":" + std::to_string(t.line(row));
}

}  // namespace

void ReadRunouts(const CsvTable& t, const TableColumns& c, ObservationSet& out) {
  t.Require({"observed_runout_m"});
  for (int row = 0; row < t.rows(); ++row) {
    if (t.Empty(row, "observed_runout_m")) continue;
    out.scalars.push_back({Quantity::kRunout, RunOf(t, c, row),
                           t.NonNegativeNumber(row, "observed_runout_m"), Where(t, row)});
  }
}

void ReadDeposits(const CsvTable& t, const TableColumns& c, ObservationSet& out) {
  t.Require({"x_m", "y_m"});
  for (int row = 0; row < t.rows(); ++row) {
    if (t.Empty(row, "x_m") && t.Empty(row, "y_m")) continue;
    DepositObservation d;
    d.run = RunOf(t, c, row);
    d.xy_m = Eigen::Vector2d(t.Number(row, "x_m"), t.Number(row, "y_m"));
    if (!t.Empty(row, "radius_m")) d.radius_m = t.NonNegativeNumber(row, "radius_m");
    d.where = Where(t, row);
    out.deposits.push_back(d);
  }
}

std::vector<std::pair<std::string, std::optional<double>>> FirstAngularSpeeds(
    const CsvTable& samples, const TableColumns& columns) {
  samples.Require({columns.run, "time_s", "omega_x_radps", "omega_y_radps", "omega_z_radps"});
  std::vector<std::pair<std::string, std::optional<double>>> out;
  std::unordered_map<std::string, std::size_t> index;
  std::vector<double> first_time_s;
  for (int row = 0; row < samples.rows(); ++row) {
    const std::string run = RunOf(samples, columns, row);
    const double time_s = samples.Number(row, "time_s");
    const auto [it, added] = index.emplace(run, out.size());
    if (!added && time_s >= first_time_s[it->second]) continue;
    std::optional<double> speed;
    if (!samples.Empty(row, "omega_x_radps") || !samples.Empty(row, "omega_y_radps") ||
        !samples.Empty(row, "omega_z_radps"))
      speed = Eigen::Vector3d(samples.Number(row, "omega_x_radps"),
                              samples.Number(row, "omega_y_radps"),
                              samples.Number(row, "omega_z_radps"))
                  .norm();
    if (added) {
      out.emplace_back(run, speed);
      first_time_s.push_back(time_s);
    } else {
      out[it->second].second = speed;
      first_time_s[it->second] = time_s;
    }
  }
  return out;
}

void ReadImpacts(const CsvTable& t, const TableColumns& c, ObservationSet& out,
                 const CsvTable* next_samples) {
  std::unordered_map<std::string, std::optional<double>> next_omega;
  if (next_samples) {
    t.Require({c.next_run});
    for (auto& [run, speed] : FirstAngularSpeeds(*next_samples, c)) next_omega[run] = speed;
  }
  const bool vectors = t.Has("incoming_vx_mps");
  if (vectors) {
    t.Require({"incoming_vx_mps", "incoming_vy_mps", "incoming_vz_mps", "outgoing_vx_mps",
               "outgoing_vy_mps", "outgoing_vz_mps"});
  } else {
    t.Require({"incoming_speed_mps", "outgoing_speed_mps"});
  }
  for (int row = 0; row < t.rows(); ++row) {
    double in = 0, out_speed = 0;
    if (vectors) {
      const auto v = [&](const char* x, const char* y, const char* z) {
        return Eigen::Vector3d(t.Number(row, x), t.Number(row, y), t.Number(row, z));
      };
      in = v("incoming_vx_mps", "incoming_vy_mps", "incoming_vz_mps").norm();
      out_speed = v("outgoing_vx_mps", "outgoing_vy_mps", "outgoing_vz_mps").norm();
    } else {
      in = t.NonNegativeNumber(row, "incoming_speed_mps");
      out_speed = t.NonNegativeNumber(row, "outgoing_speed_mps");
    }
    if (in <= 0)
      throw InputError(Where(t, row) + ": incoming speed 0: an impact needs an incoming velocity");
    const std::string run = RunOf(t, c, row);
    out.scalars.push_back({Quantity::kImpactSpeedOut, run, out_speed, Where(t, row)});
    out.scalars.push_back(
        {Quantity::kImpactEnergyRatio, run, (out_speed * out_speed) / (in * in), Where(t, row)});
    if (!t.Empty(row, "omega_out_radps")) {
      out.scalars.push_back({Quantity::kImpactAngularSpeedOut, run,
                             t.NonNegativeNumber(row, "omega_out_radps"), Where(t, row)});
    } else if (next_samples && !t.Empty(row, c.next_run)) {
      const std::string next = t.Text(row, c.next_run);
      const auto it = next_omega.find(next);
      if (it == next_omega.end())
        throw InputError(t.Where(row, c.next_run) + ": segment '" + next + "' has no sample in " +
                         next_samples->path());
      if (it->second)
        out.scalars.push_back({Quantity::kImpactAngularSpeedOut, run, *it->second, Where(t, row)});
    }
    if (!t.Empty(row, "duration_s"))
      out.scalars.push_back(
          {Quantity::kImpactDuration, run, t.NonNegativeNumber(row, "duration_s"), Where(t, row)});
  }
}

void ReadImpacts(const CsvTable& t, const TableColumns& c, ObservationSet& out) {
  ReadImpacts(t, c, out, nullptr);
}

void ReadScars(const CsvTable& t, const TableColumns& c, ObservationSet& out) {
  t.Require({"scar_length_m"});
  for (int row = 0; row < t.rows(); ++row) {
    if (t.Empty(row, "scar_length_m")) continue;
    out.scalars.push_back({Quantity::kScarLength, RunOf(t, c, row),
                           t.NonNegativeNumber(row, "scar_length_m"), Where(t, row)});
  }
}

void ReadZoneObservations(const CsvTable& t, const TableColumns& c, ObservationSet& out) {
  t.Require({"zone_id", "quantity", "value"});
  for (int row = 0; row < t.rows(); ++row) {
    if (t.Empty(row, "value")) continue;
    const std::string id = t.Text(row, "zone_id");
    int zone = -1;
    std::string known;
    for (std::size_t k = 0; k < out.zones.size(); ++k) {
      if (out.zones[k].id == id) zone = static_cast<int>(k);
      known += (known.empty() ? "" : ", ") + out.zones[k].id;
    }
    if (zone < 0)
      throw InputError(t.Where(row, "zone_id") + ": unknown zone '" + id +
                       "' (the event's zones: " + (known.empty() ? "none" : known) + ")");
    const std::string q = t.Text(row, "quantity");
    Quantity quantity;
    if (q == "speed_mps") {
      quantity = Quantity::kZoneSpeed;
    } else if (q == "angular_speed_radps") {
      quantity = Quantity::kZoneAngularSpeed;
    } else if (q == "jump_height_m") {
      quantity = Quantity::kZoneJumpHeight;
    } else if (q == "passed") {
      quantity = Quantity::kZonePassed;
    } else {
      throw InputError(t.Where(row, "quantity") + ": unknown quantity '" + q +
                       "' (known: speed_mps, angular_speed_radps, jump_height_m, passed)");
    }
    const double value = quantity == Quantity::kZoneJumpHeight ? t.Number(row, "value")
                                                               : t.NonNegativeNumber(row, "value");
    if (quantity == Quantity::kZonePassed && value != 0 && value != 1)
      throw InputError(t.Where(row, "value") + ": passed is 0 or 1, not " + t.Text(row, "value"));
    ScalarObservation o{quantity, RunOf(t, c, row), value, Where(t, row)};
    o.zone = zone;
    out.scalars.push_back(o);
  }
}

void ReadTrajectories(const CsvTable& t, const TableColumns& c, const Terrain& terrain,
                      ObservationSet& out) {
  t.Require({"time_s", "x_m", "y_m", "z_m"});
  const bool speeds = t.Has("speed_mps");
  if (!speeds) t.Require({"vx_mps", "vy_mps", "vz_mps"});
  const bool omega = t.Has("omega_x_radps");
  if (omega) t.Require({"omega_x_radps", "omega_y_radps", "omega_z_radps"});
  // Runs in the order of their first row; each run's rows in table order.
  std::vector<std::string> runs;
  std::vector<std::vector<int>> rows;
  for (int row = 0; row < t.rows(); ++row) {
    const std::string run = RunOf(t, c, row);
    std::size_t k = 0;
    while (k < runs.size() && runs[k] != run) ++k;
    if (k == runs.size()) {
      runs.push_back(run);
      rows.emplace_back();
    }
    rows[k].push_back(row);
  }
  for (std::size_t k = 0; k < runs.size(); ++k) {
    const std::vector<int>& r = rows[k];
    const std::string where = Where(t, r.front());
    if (r.size() < 2)
      throw InputError(where + ": run '" + runs[k] + "' has a single trajectory sample");
    double max_speed = 0, omega_sum = 0, max_jump = -1e300;
    bool jump = false, every_omega = omega;
    double previous_t = -1e300;
    for (int row : r) {
      const double time = t.Number(row, "time_s");
      if (time <= previous_t)
        throw InputError(t.Where(row, "time_s") + ": times of run '" + runs[k] + "' must increase");
      previous_t = time;
      const double speed = speeds
                               ? t.NonNegativeNumber(row, "speed_mps")
                               : Eigen::Vector3d(t.Number(row, "vx_mps"), t.Number(row, "vy_mps"),
                                                 t.Number(row, "vz_mps"))
                                     .norm();
      max_speed = std::max(max_speed, speed);
      if (omega && (t.Empty(row, "omega_x_radps") || t.Empty(row, "omega_y_radps") ||
                    t.Empty(row, "omega_z_radps")))
        every_omega = false;
      else if (omega)
        omega_sum += Eigen::Vector3d(t.Number(row, "omega_x_radps"), t.Number(row, "omega_y_radps"),
                                     t.Number(row, "omega_z_radps"))
                         .norm();
      TerrainSample ground;
      const double x = t.Number(row, "x_m"), y = t.Number(row, "y_m"), z = t.Number(row, "z_m");
      if (terrain.Sample(x, y, &ground)) {
        max_jump = std::max(max_jump, (z - ground.height_m) * ground.normal.z());
        jump = true;
      }
    }
    const double window = t.Number(r.back(), "time_s") - t.Number(r.front(), "time_s");
    out.scalars.push_back({Quantity::kSegmentMaxSpeed, runs[k], max_speed, where, window});
    if (every_omega)
      out.scalars.push_back({Quantity::kSegmentMeanAngularSpeed, runs[k],
                             omega_sum / double(r.size()), where, window});
    if (jump)
      out.scalars.push_back({Quantity::kSegmentMaxJumpHeight, runs[k], max_jump, where, window});
  }
}

}  // namespace talus::fieldobs
