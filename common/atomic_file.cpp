#include "common/atomic_file.hpp"

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <system_error>

namespace talus {

AtomicFile::AtomicFile(std::string final_path) : final_path_(std::move(final_path)) {
  const std::filesystem::path p(final_path_);
  std::string name = ".";
  name += p.filename().string();
  name += ".tmp-";
  name += std::to_string(::getpid());
  temp_path_ = (p.parent_path() / name).string();
}

AtomicFile::~AtomicFile() {
  if (!committed_) {
    std::error_code ignored;
    std::filesystem::remove(temp_path_, ignored);
  }
}

void AtomicFile::Commit() {
  std::error_code error;
  std::filesystem::rename(temp_path_, final_path_, error);
  if (error)
    throw std::runtime_error("cannot rename " + temp_path_ + " to " + final_path_ + ": " +
                             error.message());
  committed_ = true;
}

void WriteFileAtomically(const std::string& path, const std::string& contents) {
  AtomicFile file(path);
  {
    std::ofstream out(file.temp_path(), std::ios::binary);
    out << contents;
    out.flush();
    if (!out) throw std::runtime_error("cannot write " + file.temp_path());
  }
  file.Commit();
}

}  // namespace talus
