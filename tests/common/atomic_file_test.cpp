#include "common/atomic_file.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <stdexcept>

namespace talus {
namespace {

// An empty directory of its own under the system's temporary directory.
std::filesystem::path FreshDir(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / ("talus_common_test_" + name);
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

int FilesIn(const std::filesystem::path& dir) {
  int n = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) n += entry.is_regular_file();
  return n;
}

TEST(AtomicFile, CompleteOrAbsent) {
  const auto dir = FreshDir("atomic");
  const auto path = (dir / "out.txt").string();
  {
    AtomicFile file(path);
    std::ofstream(file.temp_path()) << "half";
    EXPECT_FALSE(std::filesystem::exists(path));
  }  // not committed: nothing remains
  EXPECT_EQ(FilesIn(dir), 0);
  WriteFileAtomically(path, "whole\n");
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "whole");
  EXPECT_EQ(FilesIn(dir), 1);
  EXPECT_THROW(WriteFileAtomically((dir / "no_such_dir" / "x.txt").string(), "x"),
               std::runtime_error);
}

}  // namespace
}  // namespace talus
