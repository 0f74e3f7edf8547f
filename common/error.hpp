#pragma once
// Bad input: thrown before any work starts, with a message that names the file, key or line.

#include <stdexcept>
#include <string>

namespace talus {

class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace talus
