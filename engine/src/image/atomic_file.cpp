#include "image/atomic_file.h"

#include <unistd.h>

#include <atomic>
#include <cstdint>
#include <exception>
#include <stdexcept>
#include <string>
#include <system_error>

namespace tilesplat::detail {
namespace {

std::filesystem::path directory_of(const std::filesystem::path& target) {
  std::filesystem::path directory = target.parent_path();
  return directory.empty() ? std::filesystem::path(".") : directory;
}

// Unique among concurrent writers: the pid separates processes, the counter threads and calls.
std::filesystem::path temp_path_beside(const std::filesystem::path& target) {
  static std::atomic<std::uint64_t> counter{0};
  const std::uint64_t serial = counter.fetch_add(1, std::memory_order_relaxed);
  // A leading dot keeps half-written files out of casual listings and globs like *.exr. Built by
  // appending: GCC 12 misreports '"." + text + ...' under -Wrestrict.
  std::string name(1, '.');
  name += target.filename().string();
  name += ".tmp-";
  name += std::to_string(::getpid());
  name += '-';
  name += std::to_string(serial);
  return directory_of(target) / name;
}

std::string describe_current_exception() {
  try {
    throw;
  } catch (const std::exception& error) {
    return error.what();
  } catch (...) {
    return "unknown error";
  }
}

}  // namespace

void write_file_atomically(const std::filesystem::path& target,
                           const std::function<void(const std::filesystem::path& temp)>& write) {
  const std::string prefix = "cannot write " + target.string() + ": ";
  if (target.filename().empty() || target.filename() == "." || target.filename() == "..")
    throw std::runtime_error(prefix + "the path does not name a file");

  // Checked up front because the error the writer would report concerns the temporary name,
  // which means nothing to the user.
  const std::filesystem::path directory = directory_of(target);
  std::error_code status_error;
  const auto directory_status = std::filesystem::status(directory, status_error);
  if (!std::filesystem::exists(directory_status))
    throw std::runtime_error(prefix + "directory '" + directory.string() + "' does not exist");
  if (!std::filesystem::is_directory(directory_status))
    throw std::runtime_error(prefix + "'" + directory.string() + "' is not a directory");

  const std::filesystem::path temp = temp_path_beside(target);
  try {
    write(temp);
    std::filesystem::rename(temp, target);
  } catch (...) {
    std::error_code ignored;
    std::filesystem::remove(temp, ignored);
    std::throw_with_nested(std::runtime_error(prefix + describe_current_exception()));
  }
}

}  // namespace tilesplat::detail
