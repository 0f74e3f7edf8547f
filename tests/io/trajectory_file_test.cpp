#include "io/trajectory_file.hpp"

#include <H5Cpp.h>
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <fstream>
#include <sstream>
#include <thread>

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

// Rocks read back and written again (as talus merge does) give the original file's bytes.
TEST(TrajectoryReader, RocksReadBackAndWrittenAgainGiveTheSameBytes) {
  const auto dir = testing::FreshDir("h5_read");
  const auto first = (dir / "first.h5").string(), second = (dir / "second.h5").string();
  const RockShape shape = MakeRockShape(MakeBox(1, 2, 3), 2000);
  auto own = std::make_shared<RockShape>(MakeRockShape(MakeBox(1, 1, 1), 2500));
  {
    TrajectoryWriter writer(first, shape);
    ensemble::RockOutcome a = Rock(3, 40), b = Rock(4, 0);
    a.shape = own;
    a.trajectory[5].orientation = Eigen::Quaterniond(0.5, -0.5, 0.5, 0.5);
    writer.Write(a);
    writer.Write(b);
    writer.Commit();
  }
  {
    const TrajectoryReader reader(first);
    const StoredTrajectory a = reader.Read(3);
    EXPECT_EQ(a.mass_kg, own->mass_kg);
    ASSERT_EQ(a.samples.size(), 40u);
    EXPECT_EQ(a.samples[5].orientation.x(), -0.5);
    EXPECT_EQ(a.samples[7].position_m.y(), 14);
    EXPECT_THROW(reader.Read(5), std::runtime_error);
    TrajectoryWriter writer(second, shape);
    writer.Write(3, a);
    writer.Write(4, reader.Read(4));
    writer.Commit();
  }
  const auto slurp = [](const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream bytes;
    bytes << in.rdbuf();
    return bytes.str();
  };
  EXPECT_TRUE(slurp(first) == slurp(second));
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

std::string Slurp(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// Writes up to `rocks` rocks of `samples` samples and commits; returns the message of the
// exception that stopped it ("" if none).
std::string WriteUntilFailure(const std::string& path, int rocks, int samples) {
  try {
    TrajectoryWriter writer(path, MakeRockShape(MakeBox(1, 1, 1), 2000));
    for (int k = 0; k < rocks; ++k) writer.Write(Rock(k, samples));
    writer.Commit();
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

// A full disk: the writer's temporary file (".trajectories.h5.tmp-<pid>", common/atomic_file.hpp)
// is made /dev/full, on which every write fails with ENOSPC. One exception naming the file and
// the reason, nothing left behind, and no crash in HDF5's shutdown at exit (ctest runs each test
// in a process of its own; HDF5's C++ API used to print "H5Dclose failed" for every dataset and
// then crash there).
TEST(TrajectoryWriter, FullDiskIsOneErrorNamingTheFileAndLeavesNothing) {
  const auto dir = testing::FreshDir("full");
  const auto path = (dir / "trajectories.h5").string();
  std::filesystem::create_symlink("/dev/full",
                                  dir / (".trajectories.h5.tmp-" + std::to_string(::getpid())));
  const std::string message = WriteUntilFailure(path, 20, 200);
  EXPECT_NE(message.find(path + ": No space left on device"), std::string::npos) << message;
  EXPECT_TRUE(std::filesystem::is_empty(dir));
}

// A file-size limit (EFBIG once the file passes it) fails the same way, at whichever rock.
TEST(TrajectoryWriter, FileSizeLimitIsOneErrorAndLeavesNothing) {
  const auto dir = testing::FreshDir("limit");
  const auto path = (dir / "trajectories.h5").string();
  rlimit old{};
  ASSERT_EQ(::getrlimit(RLIMIT_FSIZE, &old), 0);
  constexpr rlim_t kLimit = 64 * 1024;
  if (old.rlim_max != RLIM_INFINITY && old.rlim_max < 4 * kLimit)
    GTEST_SKIP() << "the hard file-size limit is already below " << 4 * kLimit << " bytes";
  std::signal(SIGXFSZ, SIG_IGN);  // else the process is killed at the limit
  const rlimit small{kLimit, old.rlim_max};
  ASSERT_EQ(::setrlimit(RLIMIT_FSIZE, &small), 0);
  const std::string message = WriteUntilFailure(path, 2000, 400);
  ::setrlimit(RLIMIT_FSIZE, &old);
  EXPECT_NE(message.find(path + ": File too large"), std::string::npos) << message;
  EXPECT_NE(message.find("cannot write rock "), std::string::npos) << message;
  EXPECT_TRUE(std::filesystem::is_empty(dir));
}

// The determinism contract covers trajectories.h5: no object timestamps, so the same rocks
// written at different times give the same bytes.
TEST(TrajectoryWriter, SameRocksGiveTheSameBytesAtAnyTime) {
  const auto dir = testing::FreshDir("same");
  const auto a = dir / "a.h5", b = dir / "b.h5";
  EXPECT_EQ(WriteUntilFailure(a.string(), 3, 30), "");
  std::this_thread::sleep_for(std::chrono::milliseconds(1100));  // timestamps are in seconds
  EXPECT_EQ(WriteUntilFailure(b.string(), 3, 30), "");
  EXPECT_TRUE(Slurp(a) == Slurp(b)) << "the files differ";
  H5::H5File file(a.string(), H5F_ACC_RDONLY);
  for (const char* name : {"/rocks", "/rocks/2", "/rocks/2/position", "/rocks/2/contact"}) {
    H5O_info_t info;
    ASSERT_GE(H5Oget_info_by_name2(file.getId(), name, &info, H5O_INFO_TIME, H5P_DEFAULT), 0);
    EXPECT_EQ(info.ctime, 0) << name;
    EXPECT_EQ(info.mtime, 0) << name;
    EXPECT_EQ(info.btime, 0) << name;
    EXPECT_EQ(info.atime, 0) << name;
  }
}

}  // namespace
}  // namespace talus::io
