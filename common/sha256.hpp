#pragma once
// SHA-256 (FIPS 180-4, through OpenSSL's libcrypto) as 64 lower-case hex digits: the hash of the
// inputs that outputs record ("inputs_sha256") and the checksum of files that talus writes and
// reads back (a calibration checkpoint, a partial result). It detects damage and hand edits; it is
// not a signature, since anyone who changes a file can compute it again.

#include <cstdint>
#include <istream>
#include <memory>
#include <string>
#include <string_view>

namespace talus {

// The SHA-256 of `bytes`, hex.
std::string Sha256Hex(std::string_view bytes);

// The same over bytes that come piece by piece (files read in chunks): the hash of everything
// added so far, in order.
class Sha256 {
 public:
  Sha256();
  ~Sha256();
  Sha256(Sha256&&) noexcept;
  Sha256& operator=(Sha256&&) noexcept;
  Sha256(const Sha256&) = delete;
  Sha256& operator=(const Sha256&) = delete;

  Sha256& Add(std::string_view bytes);
  // Adds what `in` holds from where it is to its end, in chunks; returns the number of bytes
  // added. The caller checks in.bad() for a read error.
  std::uint64_t AddStream(std::istream& in);
  // The hash of what was added so far, hex; more may be added after.
  std::string HexDigest() const;

 private:
  struct Context;
  std::unique_ptr<Context> context_;
};

}  // namespace talus
