#pragma once
// Files that are complete or absent: written under a temporary name in the target directory and
// renamed into place only when complete. Temporary names are ".<name>.talus-tmp-<pid>", so that a
// later run can tell the leftovers of a talus process that died (RemoveStaleTemporaries) from
// anything else, a user's own ".<name>.tmp-<pid>" files included.

#include <cstdio>
#include <string>
#include <vector>

namespace talus {

class AtomicFile {
 public:
  explicit AtomicFile(std::string final_path);
  ~AtomicFile();  // removes the temporary file unless committed
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  const std::string& temp_path() const { return temp_path_; }
  const std::string& final_path() const { return final_path_; }
  // Renames the temporary file to the final name (atomic on one file system). Throws on failure.
  void Commit();

 private:
  std::string final_path_;
  std::string temp_path_;
  bool committed_ = false;
};

// A text file written line by line under a temporary name (AtomicFile) and renamed into place by
// Commit(), which fails when any write failed (a full disk): the CSV writers' common part.
class AtomicTextFile {
 public:
  // Creates the temporary file and writes `first_line` and a newline. Throws std::runtime_error.
  AtomicTextFile(std::string final_path, const char* first_line);
  ~AtomicTextFile();  // closes and removes the temporary file unless committed
  AtomicTextFile(const AtomicTextFile&) = delete;
  AtomicTextFile& operator=(const AtomicTextFile&) = delete;

  std::FILE* get() const { return out_; }
  // Flushes, closes and renames into place. Throws std::runtime_error naming the file.
  void Commit();

 private:
  AtomicFile file_;
  std::FILE* out_ = nullptr;
};

// Writes `contents` to `path` atomically. Throws std::runtime_error naming the file and the reason.
void WriteFileAtomically(const std::string& path, const std::string& contents);

// Files written together: each is written under its final name in a hidden staging directory
// `<dir>/.talus-run.talus-tmp-<pid>`, and Commit() moves them into `dir` only when all are complete.
// Until then `dir` is untouched (an earlier run's files in it stay as they were); the staging
// directory and whatever is in it are removed unless committed.
class StagingDirectory {
 public:
  // Creates the staging directory in the existing directory `dir`. Throws std::runtime_error.
  explicit StagingDirectory(std::string dir);
  ~StagingDirectory();
  StagingDirectory(const StagingDirectory&) = delete;
  StagingDirectory& operator=(const StagingDirectory&) = delete;

  // Where to write the file that will become `<dir>/<name>`.
  std::string path(const std::string& name) const;
  const std::string& staging_path() const { return staging_; }
  // `message` with the staging directory's path replaced by the target directory's, for errors
  // that name a file being written.
  std::string Describe(std::string message) const;
  // Renames the staged files `names`, in this order, into the target directory (replacing files
  // of the same name) and removes the staging directory. Throws std::runtime_error.
  void Commit(const std::vector<std::string>& names);

 private:
  std::string dir_;
  std::string staging_;
};

// Removes from `dir` the temporary files and staging directories (".<name>.talus-tmp-<pid>") of
// processes that no longer exist; those of live processes, and every other file, are left alone.
// Returns the names removed. Errors (an unreadable directory) are ignored: this is housekeeping.
std::vector<std::string> RemoveStaleTemporaries(const std::string& dir);

// Makes `path` a directory of this user's alone, for files of its own (a rank's staging area in a
// shared $TMPDIR): creates it with mode 0700, or accepts an existing one only when it is a
// directory, not a symbolic link, and owned by this user (its mode is then set to 0700). Throws
// std::runtime_error naming the path and why it is refused (a link someone else planted would
// lead files, and their removal, elsewhere).
void MakePrivateDirectory(const std::string& path);

}  // namespace talus
