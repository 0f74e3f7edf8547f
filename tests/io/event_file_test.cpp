// Event files: the observation tables they name, with the impacts' angular speed taken from a
// table of trajectory samples (omega_from), and errors naming file, line and key.

#include "io/event_file.hpp"

#include <gtest/gtest.h>

#include <algorithm>

#include "common/error.hpp"
#include "test_files.hpp"

namespace talus::io {
namespace {

#define EXPECT_HAS(text, part) EXPECT_NE(std::string(text).find(part), std::string::npos) << (text)

// Two flight segments of one block on a plane; the impact ends segment s0 and starts s1.
std::filesystem::path MakeEventDir(const std::string& name, const std::string& observations) {
  const auto dir = testing::FreshDir(name);
  testing::WriteText(dir / "scene.toml",
                     "[terrain]\nplane = {}\n[rock]\nshape = { box = [0.4, 0.4, 0.4] }\n"
                     "[release]\nruns = \"runs.csv\"\n");
  testing::WriteText(dir / "runs.csv", "trajectory_id,x_m,y_m\ns0,10,0\ns1,12,0\n");
  testing::WriteText(dir / "contacts.csv",
                     "trajectory_id,next_segment_id,incoming_vx_mps,incoming_vy_mps,"
                     "incoming_vz_mps,outgoing_vx_mps,outgoing_vy_mps,outgoing_vz_mps\n"
                     "s0,s1,3,0,-4,2,0,0\n");
  testing::WriteText(dir / "samples.csv",
                     "trajectory_id,time_s,omega_x_radps,omega_y_radps,omega_z_radps\n"
                     "s0,0,1,0,0\ns1,0,0,6,8\ns1,0.1,0,0,1\n");
  testing::WriteText(dir / "event.toml", "scene = \"scene.toml\"\n" + observations);
  return dir;
}

std::string ErrorOf(const std::filesystem::path& dir) {
  try {
    LoadEvent((dir / "event.toml").string());
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(LoadEvent, ImpactsTakeTheirAngularSpeedFromTrajectorySamples) {
  const auto dir = MakeEventDir("omega_from",
                                "[[observations]]\nkind = \"impacts\"\nfile = \"contacts.csv\"\n"
                                "omega_from = \"samples.csv\"\n");
  const EventFile event = LoadEvent((dir / "event.toml").string());
  ASSERT_EQ(event.observations.scalars.size(), 3u);
  const fieldobs::ScalarObservation& omega = event.observations.scalars[2];
  EXPECT_EQ(omega.quantity, fieldobs::Quantity::kImpactAngularSpeedOut);
  EXPECT_EQ(omega.run, "s0");
  EXPECT_NEAR(omega.value, 10.0, 1e-12);  // |(0, 6, 8)|, s1's first sample
  EXPECT_TRUE(event.needs_episodes);
  const auto has_input = [&](const char* file) {
    return std::any_of(event.inputs.begin(), event.inputs.end(), [&](const std::string& input) {
      return std::filesystem::path(input).filename() == file;
    });
  };
  EXPECT_TRUE(has_input("samples.csv"));  // hashed with the other tables
  // Without omega_from the same table gives speed and energy ratio only.
  const auto plain = MakeEventDir(
      "omega_plain", "[[observations]]\nkind = \"impacts\"\nfile = \"contacts.csv\"\n");
  EXPECT_EQ(LoadEvent((plain / "event.toml").string()).observations.scalars.size(), 2u);
}

TEST(LoadEvent, OmegaFromErrorsNameFileLineAndKey) {
  EXPECT_HAS(ErrorOf(MakeEventDir("omega_runout",
                                  "[[observations]]\nkind = \"runout\"\nfile = \"contacts.csv\"\n"
                                  "omega_from = \"samples.csv\"\n")),
             "event.toml:5: observations[0].omega_from: only impacts take omega_from");
  EXPECT_HAS(ErrorOf(MakeEventDir("omega_missing",
                                  "[[observations]]\nkind = \"impacts\"\nfile = \"contacts.csv\"\n"
                                  "omega_from = \"nothere.csv\"\n")),
             "event.toml:5: observations[0].omega_from: file not found: ");
  EXPECT_HAS(ErrorOf(MakeEventDir("omega_typo",
                                  "[[observations]]\nkind = \"impacts\"\nfile = \"contacts.csv\"\n"
                                  "omega_form = \"samples.csv\"\n")),
             "observations[0].omega_form: unknown key (did you mean 'omega_from'?)");
  const auto dir = MakeEventDir("omega_unknown_segment",
                                "[[observations]]\nkind = \"impacts\"\nfile = \"contacts.csv\"\n"
                                "omega_from = \"samples.csv\"\n");
  testing::WriteText(
      dir / "samples.csv",
      "trajectory_id,time_s,omega_x_radps,omega_y_radps,omega_z_radps\ns0,0,1,0,0\n");
  EXPECT_HAS(ErrorOf(dir), "contacts.csv:2: column 'next_segment_id': segment 's1' has no sample");
}

}  // namespace
}  // namespace talus::io
