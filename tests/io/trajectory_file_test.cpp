#include "io/trajectory_file.hpp"

#include <H5Cpp.h>
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <chrono>
#include <csignal>
#include <cstdint>
#include <cstdlib>
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
    TrajectoryWriter writer(first, shape, "");
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
    TrajectoryWriter writer(second, shape, "");
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

std::string TextAttribute(const H5::H5Object& object, const char* name) {
  const H5::Attribute attribute = object.openAttribute(name);
  std::string value;
  attribute.read(attribute.getStrType(), value);
  return value;
}

// One table per quantity over all samples and an index of the rocks (rock, first sample, count,
// shape); chunked and compressed; every dataset says its units and frame; the root its format and
// CRS.
TEST(TrajectoryWriter, TablesPerQuantityWithAnIndexOfTheRocks) {
  const auto dir = testing::FreshDir("h5");
  const auto path = (dir / "trajectories.h5").string();
  const RockShape shape = MakeRockShape(MakeBox(1, 2, 3), 2000);
  {
    TrajectoryWriter writer(path, shape, testing::Wkt(31287));
    writer.Write(Rock(0, 50));
    writer.Write(Rock(1, 3));
    writer.Write(Rock(2, 0));
    EXPECT_FALSE(std::filesystem::exists(path));
    writer.Commit();
  }
  H5::H5File file(path, H5F_ACC_RDONLY);
  EXPECT_EQ(TextAttribute(file, "format"), "talus trajectories");
  EXPECT_EQ(TextAttribute(file, "crs"), testing::Wkt(31287));
  std::int64_t version = 0;
  file.openAttribute("format_version").read(H5::PredType::NATIVE_INT64, &version);
  EXPECT_EQ(version, 2);
  H5::DataSet position = file.openDataSet("/samples/position");
  hsize_t dims[2];
  position.getSpace().getSimpleExtentDims(dims);
  EXPECT_EQ(dims[0], 53u);
  EXPECT_EQ(dims[1], 3u);
  H5::DSetCreatPropList properties = position.getCreatePlist();
  EXPECT_EQ(properties.getLayout(), H5D_CHUNKED);
  EXPECT_TRUE(properties.allFiltersAvail());
  EXPECT_GE(properties.getNfilters(), 2);  // shuffle and deflate
  std::vector<double> values(3 * 53);
  position.read(values.data(), H5::PredType::NATIVE_DOUBLE);
  EXPECT_DOUBLE_EQ(values[3 * 7 + 1], 14);        // rock 0, sample 7
  EXPECT_DOUBLE_EQ(values[3 * (50 + 2) + 2], 6);  // rock 1, sample 2
  std::vector<std::int64_t> first(3), count(3), rock(3);
  file.openDataSet("/rocks/first_sample").read(first.data(), H5::PredType::NATIVE_INT64);
  file.openDataSet("/rocks/sample_count").read(count.data(), H5::PredType::NATIVE_INT64);
  file.openDataSet("/rocks/rock").read(rock.data(), H5::PredType::NATIVE_INT64);
  EXPECT_EQ(first, (std::vector<std::int64_t>{0, 50, 53}));
  EXPECT_EQ(count, (std::vector<std::int64_t>{50, 3, 0}));
  EXPECT_EQ(rock, (std::vector<std::int64_t>{0, 1, 2}));
  std::vector<double> mass(3);
  file.openDataSet("/rocks/mass_kg").read(mass.data(), H5::PredType::NATIVE_DOUBLE);
  EXPECT_DOUBLE_EQ(mass[1], shape.mass_kg);
  const std::vector<std::array<const char*, 3>> expected = {
      {"/samples/t", "s", "none"},
      {"/samples/position", "m", "world"},
      {"/samples/quaternion", "1", "world"},
      {"/samples/velocity", "m/s", "world"},
      {"/samples/angular_velocity", "rad/s", "world"},
      {"/samples/contact", "1", "none"},
      {"/samples/scar", "m", "none"},
      {"/rocks/rock", "1", "none"},
      {"/rocks/first_sample", "1", "none"},
      {"/rocks/sample_count", "1", "none"},
      {"/rocks/mass_kg", "kg", "none"},
      {"/rocks/principal_inertia_kg_m2", "kg m2", "body"}};
  for (const auto& [name, units, frame] : expected) {
    const H5::DataSet set = file.openDataSet(name);
    EXPECT_EQ(TextAttribute(set, "units"), units) << name;
    EXPECT_EQ(TextAttribute(set, "frame"), frame) << name;
    // Deflate only where it pays: not on the doubles whose every sample differs in its mantissa.
    const std::string n = name;
    const bool stored_plain =
        n == "/samples/quaternion" || n == "/samples/velocity" || n == "/samples/scar";
    EXPECT_EQ(set.getCreatePlist().getNfilters(), stored_plain ? 0 : 2) << name;
  }
  // The plain tables read back as written.
  std::vector<double> velocity(3 * 53), quaternion(4 * 53), scar(53);
  file.openDataSet("/samples/velocity").read(velocity.data(), H5::PredType::NATIVE_DOUBLE);
  file.openDataSet("/samples/quaternion").read(quaternion.data(), H5::PredType::NATIVE_DOUBLE);
  file.openDataSet("/samples/scar").read(scar.data(), H5::PredType::NATIVE_DOUBLE);
  EXPECT_EQ(velocity[3 * 7], 1);
  EXPECT_EQ(velocity[3 * 7 + 1], 0);
  EXPECT_EQ(quaternion[4 * 52], 1);  // the identity, w first
  EXPECT_EQ(scar[7], 0.1 * 7);
  EXPECT_EQ(scar[50 + 2], 0.1 * 2);
  // A scene without a CRS.
  {
    TrajectoryWriter writer((dir / "local.h5").string(), shape, "");
    writer.Commit();
  }
  EXPECT_EQ(TextAttribute(H5::H5File((dir / "local.h5").string(), H5F_ACC_RDONLY), "crs"),
            "local metres");
}

// Rocks spanning several chunks of the tables, and rock numbers with gaps (found by bisection),
// read back as written; rocks out of order are a programming error.
TEST(TrajectoryReader, RocksAcrossChunksAndWithGapsReadBack) {
  const auto dir = testing::FreshDir("chunks");
  const auto path = (dir / "trajectories.h5").string();
  const RockShape shape = MakeRockShape(MakeBox(1, 1, 1), 2000);
  {
    TrajectoryWriter writer(path, shape, "");
    for (long k = 0; k < 300; ++k) writer.Write(Rock(k < 200 ? k : 2 * k, 97));  // 29 100 samples
    EXPECT_THROW(writer.Write(Rock(5, 1)), std::logic_error);
    writer.Commit();
  }
  const TrajectoryReader reader(path);
  EXPECT_EQ(reader.rocks(), 300);
  for (long rock : {0L, 84L, 199L, 400L, 598L}) {
    const StoredTrajectory t = reader.Read(rock);
    ASSERT_EQ(t.samples.size(), 97u) << rock;
    EXPECT_EQ(t.samples[96].position_m, Eigen::Vector3d(96, 192, 288)) << rock;
    EXPECT_EQ(t.samples[95].angular_velocity_rad_s.z(), 95) << rock;
    EXPECT_EQ(t.samples[95].contact, true) << rock;
  }
  EXPECT_THROW(reader.Read(401), std::runtime_error);
  EXPECT_THROW(reader.Read(-1), std::runtime_error);
  EXPECT_THROW(reader.Read(600), std::runtime_error);
}

TEST(TrajectoryWriter, AbandonedWriterLeavesNothing) {
  const auto dir = testing::FreshDir("abandon");
  {
    TrajectoryWriter writer((dir / "trajectories.h5").string(),
                            MakeRockShape(MakeBox(1, 1, 1), 2000), "");
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
    TrajectoryWriter writer(path, MakeRockShape(MakeBox(1, 1, 1), 2000), "");
    for (int k = 0; k < rocks; ++k) writer.Write(Rock(k, samples));
    writer.Commit();
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

// A full disk: the writer's temporary file (".trajectories.h5.talus-tmp-<pid>",
// common/atomic_file.hpp) is made /dev/full, on which every write fails with ENOSPC. One exception
// naming the file and the reason, nothing left behind, and no crash in HDF5's shutdown at exit
// (ctest runs each test in a process of its own; HDF5's C++ API used to print "H5Dclose failed" for
// every dataset and then crash there).
TEST(TrajectoryWriter, FullDiskIsOneErrorNamingTheFileAndLeavesNothing) {
  const auto dir = testing::FreshDir("full");
  const auto path = (dir / "trajectories.h5").string();
  std::filesystem::create_symlink(
      "/dev/full", dir / (".trajectories.h5.talus-tmp-" + std::to_string(::getpid())));
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

// A hard file-size limit (`ulimit -f` sets the soft and the hard one): the abandoned file's last
// writes fail too, so HDF5 cannot close it. The process must still end normally: HDF5's exit
// handler crashed on such a file (SIGSEGV at exit, after the error had been reported). In a child
// process, whose limit cannot be raised again.
TEST(TrajectoryWriter, AHardFileSizeLimitEndsTheProcessNormally) {
  const auto dir = testing::FreshDir("hard_limit");
  const auto path = (dir / "trajectories.h5").string();
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    std::signal(SIGXFSZ, SIG_IGN);
    const rlimit hard{64 * 1024, 64 * 1024};
    if (::setrlimit(RLIMIT_FSIZE, &hard) != 0) std::_Exit(3);
    const std::string message = WriteUntilFailure(path, 2000, 400);
    // exit, not _exit: the exit handlers run, as at the end of talus.
    std::exit(message.find(path + ": File too large") != std::string::npos ? 0 : 4);
  }
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFEXITED(status)) << "the child was killed by signal " << WTERMSIG(status);
  EXPECT_EQ(WEXITSTATUS(status), 0) << "3: no limit set, 4: not the expected error";
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
  for (const char* name : {"/rocks", "/samples", "/samples/position", "/rocks/rock"}) {
    H5O_info_t info;
    ASSERT_GE(H5Oget_info_by_name2(file.getId(), name, &info, H5O_INFO_TIME, H5P_DEFAULT), 0);
    EXPECT_EQ(info.ctime, 0) << name;
    EXPECT_EQ(info.mtime, 0) << name;
    EXPECT_EQ(info.btime, 0) << name;
    EXPECT_EQ(info.atime, 0) << name;
  }
}

// The reading example of docs/scenes.md ("Outputs", trajectories.h5), run with h5py on a written
// file: the documented layout is the written one.
TEST(TrajectoryWriter, DocumentedPythonExampleReadsARock) {
  // Debian's python3-h5py serves /usr/bin/python3, which another python3 on the PATH may hide.
  std::string python;
  for (const char* candidate : {"python3", "/usr/bin/python3"})
    if (python.empty() &&
        std::system((std::string(candidate) + " -c 'import h5py' >/dev/null 2>&1").c_str()) == 0)
      python = candidate;
  if (python.empty()) GTEST_SKIP() << "python3 with h5py (Debian: python3-h5py) is not installed";
  const auto dir = testing::FreshDir("python");
  std::ifstream docs(std::string(TALUS_SOURCE_DIR) + "/docs/scenes.md");
  std::string line, script;
  bool marker = false, inside = false;
  while (std::getline(docs, line)) {
    if (line.find("trajectories.h5 reading example") != std::string::npos) marker = true;
    if (marker && !inside && line.find("```python") != std::string::npos) {
      inside = true;
      continue;
    }
    if (inside && line.find("```") != std::string::npos) break;
    if (inside) script += (line.size() >= 2 ? line.substr(2) : std::string()) + "\n";
  }
  ASSERT_FALSE(script.empty()) << "no example in docs/scenes.md";
  testing::WriteText(dir / "example.py", script);
  const auto path = (dir / "trajectories.h5").string();
  {
    TrajectoryWriter writer(path, MakeRockShape(MakeBox(1, 1, 1), 2000), testing::Wkt(31287));
    for (long k = 0; k < 3; ++k) writer.Write(Rock(k, 3 + static_cast<int>(k)));
    writer.Commit();
  }
  const std::string command =
      python + " " + (dir / "example.py").string() + " " + path + " 1 > " + (dir / "out").string();
  ASSERT_EQ(std::system(command.c_str()), 0) << script;
  // Rock 1: 4 samples, the last at t = 0.03 s, position (3, 6, 9) m, angular velocity (0, 0, 3).
  EXPECT_EQ(Slurp(dir / "out"), "1 4 0.03 3.0 6.0 9.0 0.0 0.0 3.0 world\n");
}

}  // namespace
}  // namespace talus::io
