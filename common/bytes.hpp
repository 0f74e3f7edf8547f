#pragma once
// A flat byte buffer for state that moves between processes of one run (partial results on disk,
// MPI messages): plain values appended in the machine's own layout, read back in the same order.
// Readers check every length, so that a truncated or foreign buffer is an error, never a crash.

#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

namespace talus {

class ByteWriter {
 public:
  template <class T>
  void Put(const T& value) {
    static_assert(std::is_trivially_copyable_v<T>);
    const auto* p = reinterpret_cast<const char*>(&value);
    bytes_.append(p, sizeof(T));
  }
  template <class T>
  void PutVector(const std::vector<T>& values) {
    static_assert(std::is_trivially_copyable_v<T>);
    Put<std::uint64_t>(values.size());
    const auto* p = reinterpret_cast<const char*>(values.data());
    bytes_.append(p, values.size() * sizeof(T));
  }
  void PutString(const std::string& text) {
    Put<std::uint64_t>(text.size());
    bytes_.append(text);
  }
  const std::string& bytes() const { return bytes_; }
  std::string Take() { return std::move(bytes_); }

 private:
  std::string bytes_;
};

class ByteReader {
 public:
  // `what` names the buffer in errors ("partial.bin of part-3/").
  ByteReader(const std::string& bytes, std::string what) : bytes_(bytes), what_(std::move(what)) {}

  template <class T>
  T Get() {
    static_assert(std::is_trivially_copyable_v<T>);
    T value;
    std::memcpy(&value, Take(sizeof(T)), sizeof(T));
    return value;
  }
  template <class T>
  std::vector<T> GetVector() {
    const auto n = Get<std::uint64_t>();
    if (n > (bytes_.size() - at_) / sizeof(T)) Fail();
    std::vector<T> values(n);
    if (n > 0) std::memcpy(values.data(), Take(n * sizeof(T)), n * sizeof(T));
    return values;
  }
  std::string GetString() {
    const auto n = Get<std::uint64_t>();
    if (n > bytes_.size() - at_) Fail();
    return std::string(Take(n), n);
  }
  bool at_end() const { return at_ == bytes_.size(); }
  [[noreturn]] void Fail(const std::string& why = "is truncated or damaged") const {
    throw std::runtime_error(what_ + " " + why);
  }

 private:
  const char* Take(std::size_t n) {
    if (n > bytes_.size() - at_) Fail();
    const char* p = bytes_.data() + at_;
    at_ += n;
    return p;
  }
  const std::string& bytes_;
  std::string what_;
  std::size_t at_ = 0;
};

}  // namespace talus
