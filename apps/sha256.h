// SHA-256 (FIPS 180-4) of files, for outputs that name what they were made from (the EXR's scene
// checksum) and, later, for checking finished frames. Small enough to keep here rather than pull a
// crypto library into the apps.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>

namespace tilesplat::cli {

class Sha256 {
 public:
  Sha256();
  void update(std::span<const std::byte> data);
  // The digest of everything updated so far; the object is spent afterwards.
  std::array<uint8_t, 32> finish();

 private:
  void compress(const uint8_t* block);

  std::array<uint32_t, 8> state_;
  std::array<uint8_t, 64> buffer_{};
  size_t buffered_ = 0;
  uint64_t total_bytes_ = 0;
};

// Lower-case hex of the digest of `bytes`.
std::string sha256_hex(std::span<const std::byte> bytes);
// Lower-case hex of the digest of the file's contents. Throws std::runtime_error naming the file.
std::string sha256_file_hex(const std::filesystem::path& path);

}  // namespace tilesplat::cli
