#include "output_paths.h"

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <stdexcept>
#include <system_error>

#include "arg_parser.h"
#include "text.h"

namespace tilesplat::cli {

namespace fs = std::filesystem;

bool has_extension(const fs::path& path, std::string_view extension) {
  const std::string actual = path.extension().string();
  return actual.size() == extension.size() &&
         std::equal(actual.begin(), actual.end(), extension.begin(), [](char a, char b) {
           return std::tolower(static_cast<unsigned char>(a)) == std::tolower(static_cast<unsigned char>(b));
         });
}

void check_output_path(const fs::path& path, std::string_view flag) {
  if (path.empty()) throw UsageError(std::string(flag) + " expects a file name");
  std::error_code ec;
  if (fs::is_directory(path, ec))
    throw std::runtime_error("cannot write " + single_quoted(path.string()) + " (" + std::string(flag) +
                             "): it is a directory");
  fs::path directory = path.parent_path();
  if (directory.empty()) directory = ".";
  const auto status = fs::status(directory, ec);
  if (!fs::exists(status))
    throw std::runtime_error("cannot write " + single_quoted(path.string()) + " (" + std::string(flag) +
                             "): directory " + single_quoted(directory.string()) + " does not exist");
  if (!fs::is_directory(status))
    throw std::runtime_error("cannot write " + single_quoted(path.string()) + " (" + std::string(flag) +
                             "): " + single_quoted(directory.string()) + " is not a directory");
  if (::access(directory.c_str(), W_OK) != 0)
    throw std::runtime_error("cannot write " + single_quoted(path.string()) + " (" + std::string(flag) +
                             "): directory " + single_quoted(directory.string()) + " is not writable");
}

void check_distinct_paths(const std::vector<std::pair<std::string, fs::path>>& paths) {
  std::vector<std::pair<std::string, fs::path>> resolved;
  for (const auto& [flag, path] : paths) {
    if (path.empty()) continue;
    std::error_code ec;
    fs::path canonical = fs::weakly_canonical(path, ec);
    if (ec) canonical = fs::absolute(path, ec).lexically_normal();
    for (const auto& [other_flag, other] : resolved)
      if (other == canonical)
        throw UsageError(other_flag + " and " + flag + " name the same file " + single_quoted(path.string()));
    resolved.emplace_back(flag, canonical);
  }
}

}  // namespace tilesplat::cli
