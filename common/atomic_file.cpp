#include "common/atomic_file.hpp"

#include <fcntl.h>
#include <signal.h>  // NOLINT(modernize-deprecated-headers): POSIX sigaction is declared here
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <system_error>

namespace talus {
namespace {

namespace fs = std::filesystem;

constexpr const char* kTempMarker = ".talus-tmp-";

// ".<name>.talus-tmp-<pid>" in the directory of `path`.
std::string TemporaryName(const fs::path& path) {
  std::string name = ".";  // appended piece by piece: GCC 12 warns (-Wrestrict) on a + b + c
  name += path.filename().string();
  name += kTempMarker;
  name += std::to_string(::getpid());
  return (path.parent_path() / name).string();
}

// The process id a temporary name ".<name>.talus-tmp-<pid>" carries; 0 for any other name.
pid_t OwnerOf(const std::string& name) {
  const std::size_t at = name.rfind(kTempMarker);
  if (name.size() < 2 || name[0] != '.' || at == std::string::npos || at < 2) return 0;
  const char* first = name.data() + at + std::strlen(kTempMarker);
  const char* last = name.data() + name.size();
  pid_t pid = 0;
  const auto [end, error] = std::from_chars(first, last, pid);
  if (error != std::errc() || end != last || first == last || pid <= 0) return 0;
  return pid;
}

bool ProcessExists(pid_t pid) { return ::kill(pid, 0) == 0 || errno == EPERM; }

}  // namespace

AtomicFile::AtomicFile(std::string final_path)
    : final_path_(std::move(final_path)), temp_path_(TemporaryName(final_path_)) {}

AtomicFile::~AtomicFile() {
  if (!committed_) {
    std::error_code ignored;
    fs::remove(temp_path_, ignored);
  }
}

AtomicTextFile::AtomicTextFile(std::string final_path, const char* first_line)
    : file_(std::move(final_path)) {
  out_ = std::fopen(file_.temp_path().c_str(), "w");
  if (!out_) throw std::runtime_error("cannot create " + file_.temp_path());
  std::fprintf(out_, "%s\n", first_line);
}

AtomicTextFile::~AtomicTextFile() {
  if (out_) std::fclose(out_);
}

void AtomicTextFile::Commit() {
  // A failed write sets the stream's error; flushing what is buffered then fails the same way and
  // says why (a full disk, "File too large" under a file-size limit).
  errno = 0;
  const bool flushed = std::fflush(out_) == 0;
  const int error = errno;
  const bool ok = flushed && !std::ferror(out_);
  std::fclose(out_);
  out_ = nullptr;
  if (!ok)
    throw std::runtime_error("cannot write " + file_.final_path() +
                             (error != 0 ? std::string(": ") + std::strerror(error) : ""));
  file_.Commit();
}

void AtomicFile::Commit() {
  std::error_code error;
  fs::rename(temp_path_, final_path_, error);
  if (error)
    throw std::runtime_error("cannot rename " + temp_path_ + " to " + final_path_ + ": " +
                             error.message());
  committed_ = true;
}

void WriteFileAtomically(const std::string& path, const std::string& contents) {
  AtomicFile file(path);
  std::FILE* out = std::fopen(file.temp_path().c_str(), "wb");
  if (!out)
    throw std::runtime_error("cannot create " + file.temp_path() + ": " + std::strerror(errno));
  const bool written = std::fwrite(contents.data(), 1, contents.size(), out) == contents.size() &&
                       std::fflush(out) == 0;
  const int write_errno = errno;
  const bool closed = std::fclose(out) == 0;
  if (!written || !closed)
    throw std::runtime_error("cannot write " + path + ": " +
                             std::strerror(written ? errno : write_errno));
  file.Commit();
}

StagingDirectory::StagingDirectory(std::string dir)
    : dir_(std::move(dir)), staging_(TemporaryName(fs::path(dir_) / "talus-run")) {
  std::error_code error;
  fs::remove_all(staging_, error);  // a leftover of this very pid (a reused one)
  if (!fs::create_directory(staging_, error) || error)
    throw std::runtime_error("cannot create " + staging_ + ": " +
                             (error ? error.message() : std::string("it exists")));
}

StagingDirectory::~StagingDirectory() {
  std::error_code ignored;
  fs::remove_all(staging_, ignored);
}

std::string StagingDirectory::path(const std::string& name) const {
  return (fs::path(staging_) / name).string();
}

std::string StagingDirectory::Describe(std::string message) const {
  const std::string from = staging_ + "/";
  const std::string to = (fs::path(dir_) / "").string();
  for (std::size_t at = message.find(from); at != std::string::npos;
       at = message.find(from, at + to.size()))
    message.replace(at, from.size(), to);
  return message;
}

void StagingDirectory::Commit(const std::vector<std::string>& names) {
  for (const std::string& name : names) {
    std::error_code error;
    fs::rename(path(name), fs::path(dir_) / name, error);
    if (error)
      throw std::runtime_error("cannot move " + name + " into " + dir_ + ": " + error.message());
  }
  std::error_code ignored;
  fs::remove_all(staging_, ignored);
}

std::vector<std::string> RemoveStaleTemporaries(const std::string& dir) {
  std::vector<std::string> stale;
  std::error_code error;
  for (fs::directory_iterator it(dir, error), end; !error && it != end; it.increment(error)) {
    const std::string name = it->path().filename().string();
    const pid_t owner = OwnerOf(name);
    if (owner != 0 && owner != ::getpid() && !ProcessExists(owner)) stale.push_back(name);
  }
  std::vector<std::string> removed;
  for (const std::string& name : stale) {
    std::error_code ignored;
    if (fs::remove_all(fs::path(dir) / name, ignored) > 0 && !ignored) removed.push_back(name);
  }
  return removed;
}

void MakePrivateDirectory(const std::string& path) {
  const auto fail = [&](const std::string& why) {
    throw std::runtime_error(path + ": " + why +
                             "; remove it, or point TMPDIR at a directory of your own");
  };
  if (::mkdir(path.c_str(), 0700) != 0 && errno != EEXIST)
    fail(std::string("cannot create the directory: ") + std::strerror(errno));
  // Opened without following a link, then checked and fixed through the descriptor (in a sticky
  // $TMPDIR nobody else can rename or remove it afterwards).
  const int fd = ::open(path.c_str(), O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
  if (fd < 0) {
    struct stat link {};
    if (::lstat(path.c_str(), &link) == 0 && S_ISLNK(link.st_mode)) fail("is a symbolic link");
    fail(std::string("not a directory of its own (") + std::strerror(errno) + ")");
  }
  struct stat st {};
  const bool ok = ::fstat(fd, &st) == 0;
  const bool mine = ok && st.st_uid == ::geteuid();
  const bool fixed = mine && ((st.st_mode & 077) == 0 || ::fchmod(fd, 0700) == 0);
  ::close(fd);
  if (!ok) fail("cannot be examined");
  if (!mine) fail("belongs to another user (uid " + std::to_string(st.st_uid) + ")");
  if (!fixed) fail("its mode cannot be set to 0700");
}

}  // namespace talus
