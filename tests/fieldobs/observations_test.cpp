// Observation tables: each kind's columns, and errors naming file, line and column.

#include "fieldobs/observations.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "common/error.hpp"

namespace talus::fieldobs {
namespace {

std::string ErrorOf(void (*read)(const CsvTable&, const TableColumns&, ObservationSet&),
                    const std::string& text) {
  ObservationSet set;
  try {
    read(CsvTable::Parse(text, "obs.csv"), TableColumns{}, set);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

#define EXPECT_HAS(text, part) EXPECT_NE(std::string(text).find(part), std::string::npos) << (text)

TEST(Observations, RunoutsAndDepositsReadByColumnName) {
  // The Tschamut table's shape: extra columns, a quoted field with a comma.
  const CsvTable t = CsvTable::Parse(
      "trajectory_id,x_m,y_m,observed_runout_m,source\n"
      "v004,86.8,149.81,101.96,\"survey, last sample\"\n"
      "v005,68.2,161.53,,\"no runout\"\n",
      "dep.csv");
  ObservationSet set;
  ReadRunouts(t, TableColumns{}, set);
  ReadDeposits(t, TableColumns{}, set);
  ASSERT_EQ(set.scalars.size(), 1u);  // the empty runout cell is skipped
  EXPECT_EQ(set.scalars[0].quantity, Quantity::kRunout);
  EXPECT_EQ(set.scalars[0].run, "v004");
  EXPECT_EQ(set.scalars[0].value, 101.96);
  EXPECT_EQ(set.scalars[0].where, "dep.csv:2");
  ASSERT_EQ(set.deposits.size(), 2u);
  EXPECT_EQ(set.deposits[1].xy_m, Eigen::Vector2d(68.2, 161.53));
  EXPECT_FALSE(set.deposits[1].radius_m.has_value());
}

TEST(Observations, ImpactsGiveSpeedAndEnergyRatio) {
  // Incoming (3, 0, -4) m/s = 5 m/s, outgoing (2, 0, 0): speed 2 m/s, energy ratio 4/25.
  const CsvTable t = CsvTable::Parse(
      "trajectory_id,incoming_vx_mps,incoming_vy_mps,incoming_vz_mps,outgoing_vx_mps,"
      "outgoing_vy_mps,outgoing_vz_mps,omega_out_radps\n"
      "s0,3,0,-4,2,0,0,7.5\n",
      "impacts.csv");
  ObservationSet set;
  ReadImpacts(t, TableColumns{}, set);
  ASSERT_EQ(set.scalars.size(), 3u);
  EXPECT_EQ(set.scalars[0].quantity, Quantity::kImpactSpeedOut);
  EXPECT_NEAR(set.scalars[0].value, 2.0, 1e-15);
  EXPECT_EQ(set.scalars[1].quantity, Quantity::kImpactEnergyRatio);
  EXPECT_NEAR(set.scalars[1].value, 4.0 / 25.0, 1e-15);
  EXPECT_EQ(set.scalars[2].quantity, Quantity::kImpactAngularSpeedOut);
  // Speeds instead of vectors.
  ObservationSet speeds;
  ReadImpacts(CsvTable::Parse("incoming_speed_mps,outgoing_speed_mps\n10,5\n", "s.csv"),
              TableColumns{}, speeds);
  ASSERT_EQ(speeds.scalars.size(), 2u);
  EXPECT_EQ(speeds.scalars[0].run, "");  // no run column: the whole scene
  EXPECT_NEAR(speeds.scalars[1].value, 0.25, 1e-15);
}

// Chant Sura layout: contact events between flight segments, the angular speed after each impact
// from the first sample of the next segment in a table of trajectory samples.
TEST(Observations, ImpactAngularSpeedFromTheNextSegmentsFirstSample) {
  const CsvTable impacts = CsvTable::Parse(
      "trajectory_id,next_segment_id,incoming_speed_mps,outgoing_speed_mps\n"
      "r1_seg00,r1_seg01,8,4\n"
      "r1_seg01,r1_seg02,9,3\n"
      "r2_seg00,r2_seg01,5,2\n",
      "impacts.csv");
  // Samples out of time order: r1_seg01's first sample is the one at t = 0 (|(3, 4, 0)| = 5);
  // r1_seg02 starts with (0, 0, -2); r2_seg01 has no angular velocity (NaN, as the data have).
  const CsvTable samples = CsvTable::Parse(
      "trajectory_id,time_s,omega_x_radps,omega_y_radps,omega_z_radps\n"
      "r1_seg00,0,1,1,1\n"
      "r1_seg01,0.005,9,9,9\n"
      "r1_seg01,0,3,4,0\n"
      "r1_seg02,0,0,0,-2\n"
      "r1_seg02,0.01,7,0,0\n"
      "r2_seg01,0,nan,nan,nan\n",
      "samples.csv");
  const auto first = FirstAngularSpeeds(samples, TableColumns{});
  ASSERT_EQ(first.size(), 4u);
  EXPECT_EQ(first[1].first, "r1_seg01");
  EXPECT_NEAR(*first[1].second, 5.0, 1e-15);
  EXPECT_FALSE(first[3].second.has_value());
  ObservationSet set;
  ReadImpacts(impacts, TableColumns{}, set, &samples);
  std::vector<double> omega;
  std::vector<std::string> runs;
  for (const ScalarObservation& o : set.scalars)
    if (o.quantity == Quantity::kImpactAngularSpeedOut) {
      omega.push_back(o.value);
      runs.push_back(o.run);
    }
  ASSERT_EQ(omega.size(), 2u);  // r2's next segment has no angular velocity
  EXPECT_NEAR(omega[0], 5.0, 1e-15);
  EXPECT_NEAR(omega[1], 2.0, 1e-15);
  EXPECT_EQ(runs[0], "r1_seg00");  // the run whose first contact episode is the impact
  EXPECT_EQ(set.scalars.size(), 3u * 2u + 2u);
  // Without the samples: no angular speed.
  ObservationSet plain;
  ReadImpacts(impacts, TableColumns{}, plain);
  EXPECT_EQ(plain.scalars.size(), 6u);

  // Errors name the file, line and column.
  const auto error = [&](const std::string& impacts_text, const std::string& samples_text) {
    ObservationSet out;
    try {
      const CsvTable s2 = CsvTable::Parse(samples_text, "samples.csv");
      ReadImpacts(CsvTable::Parse(impacts_text, "impacts.csv"), TableColumns{}, out, &s2);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  const std::string good_samples =
      "trajectory_id,time_s,omega_x_radps,omega_y_radps,omega_z_radps\nb,0,1,0,0\n";
  EXPECT_HAS(error("trajectory_id,next_segment_id,incoming_speed_mps,outgoing_speed_mps\n"
                   "a,c,8,4\n",
                   good_samples),
             "impacts.csv:2: column 'next_segment_id': segment 'c' has no sample in samples.csv");
  EXPECT_HAS(error("trajectory_id,incoming_speed_mps,outgoing_speed_mps\na,8,4\n", good_samples),
             "impacts.csv: missing column 'next_segment_id'");
  EXPECT_HAS(error("trajectory_id,next_segment_id,incoming_speed_mps,outgoing_speed_mps\n"
                   "a,b,8,4\n",
                   "trajectory_id,time_s,omega_x_radps\nb,0,1\n"),
             "samples.csv: missing column 'omega_y_radps'");
  EXPECT_HAS(error("trajectory_id,next_segment_id,incoming_speed_mps,outgoing_speed_mps\n"
                   "a,b,8,4\n",
                   "trajectory_id,time_s,omega_x_radps,omega_y_radps,omega_z_radps\nb,0,1,nan,0\n"),
             "samples.csv:2: column 'omega_y_radps': 'nan' is not a finite number");
}

TEST(Observations, BadTablesNameFileLineAndColumn) {
  EXPECT_HAS(ErrorOf(ReadRunouts, "trajectory_id,runout\nv1,3\n"),
             "obs.csv: missing column 'observed_runout_m' (the header has: trajectory_id, runout)");
  EXPECT_HAS(ErrorOf(ReadRunouts, "trajectory_id,observed_runout_m\nv1,-3\n"),
             "obs.csv:2: column 'observed_runout_m': -3 must be >= 0");
  EXPECT_HAS(ErrorOf(ReadRunouts, "trajectory_id,observed_runout_m\nv1,1e400\n"),
             "obs.csv:2: column 'observed_runout_m': '1e400' is not a finite number");
  EXPECT_HAS(ErrorOf(ReadRunouts, "trajectory_id,observed_runout_m\n,3\n"),
             "obs.csv:2: column 'trajectory_id': empty run id");
  EXPECT_HAS(ErrorOf(ReadDeposits, "x_m,y_m\n1,2\n3\n"),
             "obs.csv:3: 1 fields, but the header has 2");
  EXPECT_HAS(ErrorOf(ReadDeposits, "x_m,y_m\n1,\"2\n"), "obs.csv:2: unclosed quote");
  EXPECT_HAS(ErrorOf(ReadImpacts, "incoming_speed_mps,outgoing_speed_mps\n0,1\n"),
             "obs.csv:2: incoming speed 0");
  EXPECT_HAS(ErrorOf(ReadImpacts, "incoming_vx_mps\n1\n"), "missing column 'incoming_vy_mps'");
  EXPECT_HAS(ErrorOf(ReadScars, "x_m,x_m\n1,2\n"), "obs.csv:1: header names column 'x_m' twice");
  EXPECT_HAS(ErrorOf(ReadScars, ""), "obs.csv: empty file");
}

TEST(Observations, ZoneObservationsNameTheirZoneAndQuantity) {
  ObservationSet set;
  set.zones.push_back({"barrier", false, {{0, 0}, {1, 0}}});
  ReadZoneObservations(CsvTable::Parse("zone_id,quantity,value\nbarrier,speed_mps,12.5\n"
                                       "barrier,passed,1\nbarrier,jump_height_m,\n",
                                       "zones.csv"),
                       TableColumns{}, set);
  ASSERT_EQ(set.scalars.size(), 2u);  // the empty value is skipped
  EXPECT_EQ(set.scalars[0].quantity, Quantity::kZoneSpeed);
  EXPECT_EQ(set.scalars[0].zone, 0);
  EXPECT_EQ(set.scalars[1].quantity, Quantity::kZonePassed);
  const auto error = [&](const std::string& text) {
    try {
      ReadZoneObservations(CsvTable::Parse(text, "zones.csv"), TableColumns{}, set);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_HAS(error("zone_id,quantity,value\nwall,passed,1\n"),
             "zones.csv:2: column 'zone_id': unknown zone 'wall' (the event's zones: barrier)");
  EXPECT_HAS(error("zone_id,quantity,value\nbarrier,energy,1\n"),
             "zones.csv:2: column 'quantity': unknown quantity 'energy'");
  EXPECT_HAS(error("zone_id,quantity,value\nbarrier,passed,0.5\n"),
             "zones.csv:2: column 'value': passed is 0 or 1, not 0.5");
}

}  // namespace
}  // namespace talus::fieldobs
