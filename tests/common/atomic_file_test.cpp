#include "common/atomic_file.hpp"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "tests/test_tmp.hpp"

namespace talus {
namespace {

namespace fs = std::filesystem;

// An empty directory of its own under the system's temporary directory.
fs::path FreshDir(const std::string& name) {
  auto dir = talus::testing::TestTmpRoot() / ("talus_common_test_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

int FilesIn(const fs::path& dir) {
  int n = 0;
  for (const auto& entry : fs::directory_iterator(dir)) n += entry.is_regular_file();
  return n;
}

std::string Slurp(const fs::path& path) {
  std::ifstream in(path);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// The id of a process that has ended (a child that exited and was reaped).
pid_t DeadPid() {
  const pid_t child = ::fork();
  if (child == 0) ::_exit(0);
  ::waitpid(child, nullptr, 0);
  return child;
}

TEST(AtomicFile, CompleteOrAbsent) {
  const auto dir = FreshDir("atomic");
  const auto path = (dir / "out.txt").string();
  {
    AtomicFile file(path);
    std::ofstream(file.temp_path()) << "half";
    EXPECT_FALSE(fs::exists(path));
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

// A text file starts with its first line, is absent until committed, and is not left behind
// when abandoned.
TEST(AtomicTextFile, FirstLineThenRowsCompleteOrAbsent) {
  const auto dir = FreshDir("atomic_text");
  const auto path = (dir / "table.csv").string();
  {
    AtomicTextFile file(path, "a,b");
    std::fprintf(file.get(), "1,2\n");
  }  // not committed
  EXPECT_EQ(FilesIn(dir), 0);
  AtomicTextFile file(path, "a,b");
  std::fprintf(file.get(), "1,2\n");
  EXPECT_FALSE(fs::exists(path));
  file.Commit();
  EXPECT_EQ(Slurp(path), "a,b\n1,2\n");
  EXPECT_EQ(FilesIn(dir), 1);
  EXPECT_THROW(AtomicTextFile((dir / "no_such_dir" / "x.csv").string(), "x"), std::runtime_error);
}

TEST(AtomicFile, ErrorsSayWhy) {
  const auto dir = FreshDir("why");
  try {
    WriteFileAtomically((dir / "no_such_dir" / "x.txt").string(), "x");
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("No such file or directory"), std::string::npos)
        << e.what();
  }
}

TEST(StagingDirectory, TargetUntouchedUntilCommit) {
  const auto dir = FreshDir("staging");
  std::ofstream(dir / "a.txt") << "earlier a";
  std::ofstream(dir / "b.txt") << "earlier b";
  {
    StagingDirectory staging(dir.string());
    EXPECT_EQ(fs::path(staging.staging_path()).parent_path(), dir);
    std::ofstream(staging.path("a.txt")) << "new a";
    EXPECT_EQ(Slurp(dir / "a.txt"), "earlier a");
    EXPECT_EQ(staging.Describe("cannot write " + staging.path("a.txt") + ": why"),
              "cannot write " + (dir / "a.txt").string() + ": why");
  }  // abandoned: the earlier files are as they were, the staging directory is gone
  EXPECT_EQ(Slurp(dir / "a.txt"), "earlier a");
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 2);
  {
    StagingDirectory staging(dir.string());
    std::ofstream(staging.path("a.txt")) << "new a";
    std::ofstream(staging.path("c.txt")) << "new c";
    staging.Commit({"a.txt", "c.txt"});
  }
  EXPECT_EQ(Slurp(dir / "a.txt"), "new a");
  EXPECT_EQ(Slurp(dir / "b.txt"), "earlier b");
  EXPECT_EQ(Slurp(dir / "c.txt"), "new c");
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 3);
}

// Only talus's own temporary names (".<name>.talus-tmp-<pid>"): a user's ".notes.tmp-<pid>"
// of a dead pid stays.
TEST(RemoveStaleTemporaries, RemovesThoseOfDeadProcessesOnly) {
  const auto dir = FreshDir("stale");
  const std::string dead = std::to_string(DeadPid());
  const std::string alive = std::to_string(::getpid());
  std::ofstream(dir / (".rocks.csv.talus-tmp-" + dead)) << "x";
  fs::create_directories(dir / (".talus-run.talus-tmp-" + dead));
  std::ofstream(dir / (".talus-run.talus-tmp-" + dead) / "rocks.csv") << "x";
  std::ofstream(dir / (".rocks.csv.talus-tmp-" + alive)) << "x";
  std::ofstream(dir / (".rocks.csv.talus-tmp-1")) << "x";   // init, always alive
  std::ofstream(dir / ("notes.talus-tmp-" + dead)) << "x";  // not a temporary name
  std::ofstream(dir / (".notes.talus-tmp-" + dead + "x")) << "x";
  std::ofstream(dir / (".notes.tmp-" + dead)) << "x";  // the user's
  fs::create_directories(dir / (".precious.tmp-" + dead));
  std::ofstream(dir / "rocks.csv") << "x";
  const std::vector<std::string> removed = RemoveStaleTemporaries(dir.string());
  EXPECT_EQ(removed.size(), 2u);
  EXPECT_FALSE(fs::exists(dir / (".rocks.csv.talus-tmp-" + dead)));
  EXPECT_FALSE(fs::exists(dir / (".talus-run.talus-tmp-" + dead)));
  for (const std::string& kept :
       {".rocks.csv.talus-tmp-" + alive, std::string(".rocks.csv.talus-tmp-1"),
        "notes.talus-tmp-" + dead, ".notes.talus-tmp-" + dead + "x", ".notes.tmp-" + dead,
        ".precious.tmp-" + dead, std::string("rocks.csv")})
    EXPECT_TRUE(fs::exists(dir / kept)) << kept;
}

// The staging directory of MPI ranks in a shared $TMPDIR: created 0700; an existing one of this
// user's is tightened to 0700; a symbolic link (anyone can plant one in /tmp) is refused without
// touching its target, and so is a file.
TEST(MakePrivateDirectory, CreatesOrAcceptsOnlyAnOwnDirectoryThatIsNoLink) {
  const auto dir = FreshDir("private");
  const auto mode = [](const fs::path& p) {
    struct stat st {};
    ::lstat(p.c_str(), &st);
    return st.st_mode & 07777;
  };
  MakePrivateDirectory((dir / "new").string());
  EXPECT_TRUE(fs::is_directory(dir / "new"));
  EXPECT_EQ(mode(dir / "new"), 0700u);
  fs::create_directory(dir / "loose");
  fs::permissions(dir / "loose", fs::perms(0755));
  MakePrivateDirectory((dir / "loose").string());
  EXPECT_EQ(mode(dir / "loose"), 0700u);
  fs::create_directories(dir / "victim" / ".precious.tmp-999999");
  fs::permissions(dir / "victim", fs::perms(0755));
  fs::create_directory_symlink(dir / "victim", dir / "link");
  try {
    MakePrivateDirectory((dir / "link").string());
    ADD_FAILURE() << "a symbolic link was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("link: is a symbolic link"), std::string::npos)
        << e.what();
  }
  EXPECT_EQ(mode(dir / "victim"), 0755u);
  EXPECT_TRUE(fs::exists(dir / "victim" / ".precious.tmp-999999"));
  std::ofstream(dir / "file") << "x";
  EXPECT_THROW(MakePrivateDirectory((dir / "file").string()), std::runtime_error);
  // Another user's directory (testable as root only: chown).
  if (::geteuid() == 0) {
    fs::create_directory(dir / "theirs", dir / "new");
    ASSERT_EQ(::chown((dir / "theirs").c_str(), 65534, 65534), 0);
    try {
      MakePrivateDirectory((dir / "theirs").string());
      ADD_FAILURE() << "another user's directory was accepted";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find("belongs to another user"), std::string::npos)
          << e.what();
    }
  }
}

}  // namespace
}  // namespace talus
