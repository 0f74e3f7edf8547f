#pragma once
// The directory under which tests write their files: the system's temporary directory, in a folder
// of this source tree's own, so that test runs of two checkouts at once (CI, several builds on one
// machine) never share a fixed path. Short on purpose: MPI tests put Open MPI's session
// directory (with its sockets) below it.

#include <filesystem>
#include <cstdio>
#include <functional>
#include <string>

namespace talus::testing {

inline std::filesystem::path TestTmpRoot() {
  char name[32];
  std::snprintf(name, sizeof name, "talus-%08zx",
                std::hash<std::string>{}(TALUS_SOURCE_DIR) & 0xffffffffu);
  return std::filesystem::temp_directory_path() / name;
}

}  // namespace talus::testing
