// SHA-256 (apps/sha256.h) against the test vectors of FIPS 180-4's examples and against coreutils'
// sha256sum on a real file.
#include <gtest/gtest.h>

#include <cstddef>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>

#include "process_support.h"
#include "sha256.h"
#include "test_support.h"

namespace {

using tilesplat::cli::Sha256;
using tilesplat::cli::sha256_file_hex;
using tilesplat::cli::sha256_hex;

std::span<const std::byte> bytes_of(std::string_view text) {
  return std::as_bytes(std::span(text.data(), text.size()));
}

TEST(Sha256, KnownVectors) {
  EXPECT_EQ(sha256_hex(bytes_of("")), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(sha256_hex(bytes_of("abc")), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(sha256_hex(bytes_of("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq")),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
  const std::string million(1000000, 'a');
  EXPECT_EQ(sha256_hex(bytes_of(million)),
            "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
}

// The digest does not depend on how the input is split: every split point of a message that spans
// the 55/56/64-byte padding boundaries.
TEST(Sha256, PiecewiseUpdatesEqualOneUpdate) {
  for (size_t length : {55u, 56u, 63u, 64u, 65u, 119u, 200u}) {
    std::string message(length, '\0');
    for (size_t i = 0; i < length; ++i) message[i] = char('a' + i % 26);
    const std::string whole = sha256_hex(bytes_of(message));
    for (size_t split = 0; split <= length; split += 7) {
      Sha256 sha;
      sha.update(bytes_of(std::string_view(message).substr(0, split)));
      sha.update(bytes_of(std::string_view(message).substr(split)));
      const auto digest = sha.finish();
      std::string hex;
      for (const auto byte : digest) {
        static constexpr char kDigits[] = "0123456789abcdef";
        hex += kDigits[byte >> 4];
        hex += kDigits[byte & 15];
      }
      EXPECT_EQ(hex, whole) << "length " << length << " split " << split;
    }
  }
}

TEST(Sha256, FileDigestEqualsCoreutilsSha256sum) {
  const std::filesystem::path scene = tilesplat::testing::bundled_playbot();
  const auto result = tilesplat::testing::run_process("", "sha256sum", {scene.string()});
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_EQ(sha256_file_hex(scene), result.out.substr(0, 64));
  EXPECT_THROW(sha256_file_hex(scene.parent_path() / "missing.ply"), std::runtime_error);
}

}  // namespace
