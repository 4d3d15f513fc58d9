// SHA-256 of files, for outputs that name what they were made from (the EXR's scene checksum) and for
// checking finished frames (the render manifest): OpenSSL's libcrypto (EVP), which the apps link.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>
#include <string>

namespace tilesplat::cli {

// An incremental digest: update() with the pieces, then finish() once.
class Sha256 {
 public:
  Sha256();
  ~Sha256();
  Sha256(const Sha256&) = delete;
  Sha256& operator=(const Sha256&) = delete;
  void update(std::span<const std::byte> data);
  // The digest of everything updated so far; the object is spent afterwards.
  std::array<uint8_t, 32> finish();

 private:
  struct Context;  // OpenSSL's EVP_MD_CTX, kept out of this header
  std::unique_ptr<Context> context_;
};

// Lower-case hex of the digest of `bytes`.
std::string sha256_hex(std::span<const std::byte> bytes);
// Lower-case hex of the digest of the file's contents. Throws std::runtime_error naming the file.
std::string sha256_file_hex(const std::filesystem::path& path);

}  // namespace tilesplat::cli
