#include "image/atomic_file.h"

#include "tilesplat/image.h"

#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdint>
#include <cstring>
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

// Flushes a file's (or a directory's) data to the storage, so that a rename that survives a crash
// names complete contents. File systems that cannot sync (EINVAL: pipes, some FUSE mounts) are let be.
void sync_path(const std::filesystem::path& path, bool directory) {
  const int fd = ::open(path.c_str(), (directory ? O_RDONLY | O_DIRECTORY : O_RDONLY) | O_CLOEXEC);
  if (fd < 0) throw std::runtime_error("cannot open " + path.string() + " to sync it: " + std::strerror(errno));
  const int status = ::fsync(fd);
  const int error = errno;
  ::close(fd);
  if (status != 0 && error != EINVAL && error != EROFS)
    throw std::runtime_error("cannot sync " + path.string() + ": " + std::strerror(error));
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
    sync_path(temp, false);
    std::filesystem::rename(temp, target);
  } catch (...) {
    std::error_code ignored;
    std::filesystem::remove(temp, ignored);
    std::throw_with_nested(std::runtime_error(prefix + describe_current_exception()));
  }
  // The rename itself is durable once the directory is synced; the target is complete either way.
  try {
    sync_path(directory, true);
  } catch (...) {
    std::throw_with_nested(std::runtime_error(prefix + describe_current_exception()));
  }
}

}  // namespace tilesplat::detail

namespace tilesplat {

void write_file_atomically(const std::filesystem::path& path, std::string_view contents) {
  detail::write_file_atomically(path, [&](const std::filesystem::path& temp) {
    const int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
    if (fd < 0) throw std::runtime_error(std::strerror(errno));
    size_t written = 0;
    while (written < contents.size()) {
      const ssize_t n = ::write(fd, contents.data() + written, contents.size() - written);
      if (n < 0 && errno == EINTR) continue;
      if (n < 0) {
        const int error = errno;
        ::close(fd);
        throw std::runtime_error(std::strerror(error));
      }
      written += size_t(n);
    }
    if (::close(fd) != 0) throw std::runtime_error(std::strerror(errno));
  });
}

}  // namespace tilesplat
