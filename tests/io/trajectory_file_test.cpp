#include "io/trajectory_file.hpp"

#include <H5Cpp.h>
#include <gtest/gtest.h>

#include "solver/shapes.hpp"
#include "test_files.hpp"

namespace talus::io {
namespace {

ensemble::RockOutcome Rock(long index, int samples) {
  ensemble::RockOutcome rock;
  rock.rock = index;
  for (int k = 0; k < samples; ++k) {
    ensemble::TrajectorySample s;
    s.t_s = 0.01 * k;
    s.position_m = Eigen::Vector3d(k, 2 * k, 3 * k);
    s.orientation = Eigen::Quaterniond::Identity();
    s.velocity_m_s = Eigen::Vector3d(1, 0, 0);
    s.angular_velocity_rad_s = Eigen::Vector3d(0, 0, k);
    s.contact = k % 2;
    s.scar_m = 0.1 * k;
    rock.trajectory.push_back(s);
  }
  return rock;
}

TEST(TrajectoryWriter, GroupsPerRockChunkedAndCompressed) {
  const auto dir = testing::FreshDir("h5");
  const auto path = (dir / "trajectories.h5").string();
  const RockShape shape = MakeRockShape(MakeBox(1, 2, 3), 2000);
  {
    TrajectoryWriter writer(path, shape);
    writer.Write(Rock(0, 50));
    writer.Write(Rock(1, 3));
    EXPECT_FALSE(std::filesystem::exists(path));
    writer.Commit();
  }
  H5::H5File file(path, H5F_ACC_RDONLY);
  H5::DataSet position = file.openDataSet("/rocks/0/position");
  hsize_t dims[2];
  position.getSpace().getSimpleExtentDims(dims);
  EXPECT_EQ(dims[0], 50u);
  EXPECT_EQ(dims[1], 3u);
  H5::DSetCreatPropList properties = position.getCreatePlist();
  EXPECT_EQ(properties.getLayout(), H5D_CHUNKED);
  EXPECT_TRUE(properties.allFiltersAvail());
  EXPECT_GE(properties.getNfilters(), 2);  // shuffle and deflate
  std::vector<double> values(150);
  position.read(values.data(), H5::PredType::NATIVE_DOUBLE);
  EXPECT_DOUBLE_EQ(values[3 * 7 + 1], 14);
  H5::DataSet quaternion = file.openDataSet("/rocks/1/quaternion");
  quaternion.getSpace().getSimpleExtentDims(dims);
  EXPECT_EQ(dims[1], 4u);
  for (const char* name : {"t", "velocity", "angular_velocity", "contact", "scar"})
    EXPECT_TRUE(file.nameExists(std::string("/rocks/1/") + name)) << name;
  double mass = 0;
  file.openGroup("/rocks/0").openAttribute("mass_kg").read(H5::PredType::NATIVE_DOUBLE, &mass);
  EXPECT_DOUBLE_EQ(mass, shape.mass_kg);
}

TEST(TrajectoryWriter, AbandonedWriterLeavesNothing) {
  const auto dir = testing::FreshDir("abandon");
  {
    TrajectoryWriter writer((dir / "trajectories.h5").string(),
                            MakeRockShape(MakeBox(1, 1, 1), 2000));
    writer.Write(Rock(0, 5));
  }
  EXPECT_TRUE(std::filesystem::is_empty(dir));
}

}  // namespace
}  // namespace talus::io
