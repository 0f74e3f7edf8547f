#include "common/sha256.hpp"

#include <openssl/evp.h>

#include <stdexcept>

namespace talus {
namespace {

// libcrypto fails only when it cannot allocate or was built without SHA-256.
void Check(int ok, const char* what) {
  if (ok != 1) throw std::runtime_error(std::string("SHA-256: ") + what + " failed (libcrypto)");
}

std::string Hex(const unsigned char* digest, unsigned int size) {
  static constexpr char kDigits[] = "0123456789abcdef";
  std::string hex;
  hex.reserve(2 * size);
  for (unsigned int k = 0; k < size; ++k) {
    hex += kDigits[digest[k] >> 4];
    hex += kDigits[digest[k] & 15];
  }
  return hex;
}

}  // namespace

struct Sha256::Context {
  EVP_MD_CTX* md = EVP_MD_CTX_new();
  Context() {
    if (!md) throw std::bad_alloc();
    Check(EVP_DigestInit_ex(md, EVP_sha256(), nullptr), "EVP_DigestInit_ex");
  }
  ~Context() { EVP_MD_CTX_free(md); }
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;
};

Sha256::Sha256() : context_(std::make_unique<Context>()) {}
Sha256::~Sha256() = default;
Sha256::Sha256(Sha256&&) noexcept = default;
Sha256& Sha256::operator=(Sha256&&) noexcept = default;

Sha256& Sha256::Add(std::string_view bytes) {
  Check(EVP_DigestUpdate(context_->md, bytes.data(), bytes.size()), "EVP_DigestUpdate");
  return *this;
}

std::uint64_t Sha256::AddStream(std::istream& in) {
  std::uint64_t added = 0;
  char chunk[1 << 16];
  while (in.read(chunk, sizeof chunk) || in.gcount() > 0) {
    const auto n = static_cast<std::size_t>(in.gcount());
    Add(std::string_view(chunk, n));
    added += n;
  }
  return added;
}

std::string Sha256::HexDigest() const {
  // Finalised on a copy, so that the hash goes on.
  EVP_MD_CTX* copy = EVP_MD_CTX_new();
  if (!copy) throw std::bad_alloc();
  unsigned char digest[EVP_MAX_MD_SIZE];
  unsigned int size = 0;
  const int ok =
      EVP_MD_CTX_copy_ex(copy, context_->md) == 1 && EVP_DigestFinal_ex(copy, digest, &size) == 1;
  EVP_MD_CTX_free(copy);
  Check(ok ? 1 : 0, "EVP_DigestFinal_ex");
  return Hex(digest, size);
}

std::string Sha256Hex(std::string_view bytes) { return Sha256().Add(bytes).HexDigest(); }

}  // namespace talus
