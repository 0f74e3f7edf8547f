// SHA-256 against the test vectors of FIPS 180-4 (NIST's "SHA256.pdf" examples), and the pieces
// of the incremental form against the whole.

#include "common/sha256.hpp"

#include <gtest/gtest.h>

#include <sstream>
#include <string>

namespace talus {
namespace {

TEST(Sha256, NistTestVectors) {
  EXPECT_EQ(Sha256Hex("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(Sha256Hex(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(Sha256Hex("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
  EXPECT_EQ(Sha256Hex(std::string(1000000, 'a')),
            "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
}

// Bytes added piece by piece hash as the whole; a digest taken on the way does not end the hash;
// zero bytes are bytes too.
TEST(Sha256, PiecesHashAsTheWhole) {
  std::string text;
  for (int k = 0; k < 5000; ++k) text += static_cast<char>((k * 131) % 256);
  const std::string whole = Sha256Hex(text);
  Sha256 pieces;
  std::size_t at = 0;
  for (std::size_t size : {0, 1, 63, 64, 65, 1000, 3807}) {
    pieces.Add(std::string_view(text).substr(at, size));
    at += size;
    if (at == 64) {
      EXPECT_EQ(pieces.HexDigest(), Sha256Hex(text.substr(0, 64)));
    }
  }
  ASSERT_EQ(at, text.size());
  EXPECT_EQ(pieces.HexDigest(), whole);
  EXPECT_EQ(pieces.HexDigest(), whole);  // taking it twice changes nothing
  EXPECT_NE(Sha256Hex(text.substr(0, 4999)), whole);
}

// A stream (a file read in 64 KiB chunks) hashes as its bytes, and its size comes back.
TEST(Sha256, AStreamHashesAsItsBytesAndCountsThem) {
  const std::string bytes = std::string(200000, 'x') + std::string("\0\1\2", 3);
  std::istringstream in(bytes);
  Sha256 hash;
  EXPECT_EQ(hash.AddStream(in), bytes.size());
  EXPECT_FALSE(in.bad());
  EXPECT_EQ(hash.HexDigest(), Sha256Hex(bytes));
  std::istringstream empty("");
  EXPECT_EQ(Sha256().AddStream(empty), 0u);
}

}  // namespace
}  // namespace talus
