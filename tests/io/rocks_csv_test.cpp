#include "io/rocks_csv.hpp"

#include <gtest/gtest.h>

#include <fstream>

#include "test_files.hpp"

namespace talus::io {
namespace {

TEST(RocksCsvWriter, OneRowPerRockWithTheContractColumns) {
  const auto dir = testing::FreshDir("csv");
  const auto path = (dir / "rocks.csv").string();
  {
    ensemble::ReleaseSpec release;
    release.seed = 7;
    release.blocks.push_back({"plate, thin", nullptr, {}, {}});
    release.runs.resize(2);
    release.runs[0].id = "v001";
    release.runs[1].id = "v002";
    release.runs[1].block = 0;
    // Flat ground 10 x 10 m of the default category, medium.
    Scene scene;
    scene.terrain = Terrain(MakePlaneHeightfield(PlaneSpec{0, 10, 0, 10, 1}),
                            scene.ground.IndexOfName("medium"));
    RocksCsvWriter csv(path, scene, release);
    for (long k = 0; k < 3; ++k) {
      ensemble::RockOutcome rock;
      rock.rock = k;
      rock.release = 1;
      rock.start.position_m = Eigen::Vector3d(0, 0, 10);
      rock.result.end = EndReason::kRest;
      rock.result.final_state.position_m = Eigen::Vector3d(3, 4, 1);
      rock.result.max_speed_m_s = 12.5;
      rock.result.runout_m = 5;
      csv.Write(rock);
    }
    EXPECT_FALSE(std::filesystem::exists(path));  // complete or absent
    csv.Commit();
  }
  std::ifstream in(path);
  std::string header, row;
  std::getline(in, header);
  EXPECT_EQ(
      header,
      "rock,release,run,seed,end,x_end,y_end,z_end,runout_m,path_length_m,travel_time_s,"
      "max_speed_m_s,max_kinetic_energy_j,max_jump_height_m,max_angular_speed_rad_s,max_scar_m,"
      "block,mass_kg,x_start,y_start,z_start,travel_angle_deg,end_ground,end_barrier");
  std::getline(in, row);
  // The run's id, its block's id quoted because it holds a comma; start, the travel angle
  // atan(9 m drop / 5 m runout) = 60.94539590 deg, and the ground where it ended.
  EXPECT_EQ(row,
            "0,1,v002,7,rest,3,4,1,5,0,0,12.5,0,0,0,0,\"plate, thin\",0,0,0,10,60.9453959,medium,");
  int rows = 1;
  while (std::getline(in, row)) ++rows;
  EXPECT_EQ(rows, 3);
}

TEST(RocksCsvWriter, AbandonedWriterLeavesNothing) {
  const auto dir = testing::FreshDir("abandon");
  ensemble::ReleaseSpec release;
  const Scene scene;
  { RocksCsvWriter csv((dir / "rocks.csv").string(), scene, release); }
  EXPECT_TRUE(std::filesystem::is_empty(dir));
}

}  // namespace
}  // namespace talus::io
