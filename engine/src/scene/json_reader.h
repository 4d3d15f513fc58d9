// Reading a JSON document that people write by hand (scene descriptions, docs/scene-format.md): every
// mistake is a SceneError naming the file, the JSON path of the value ("cameras[2].fx"), what is
// wrong and what is allowed, with a "did you mean" for a misspelt key or value. Duplicate keys, which
// nlohmann would silently resolve to the last, are mistakes too.
#pragma once

#include <algorithm>
#include <array>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "text/quoting.h"

namespace tilesplat::json_reader {

using ::tilesplat::single_quoted;  // text/quoting.h

using nlohmann::json;

// The largest coordinate a position or direction may have: beyond it a value cannot be meant.
inline constexpr double kMaxCoordinate = 1e9;

// '%g' with up to 10 significant digits.
std::string format_number(double value);
// "a.b", "a[3]": the JSON path of a member or element.
std::string child_path(const std::string& parent, std::string_view key);
std::string element_path(const std::string& parent, size_t index);
std::string lowercase(std::string_view text);
size_t edit_distance(std::string_view a, std::string_view b);
// "an object", "a string", "true", "12.5": what a value is, for messages.
std::string type_name(const json& value);

template <size_t N>
std::string quoted_list(const std::array<std::string_view, N>& items) {
  std::string out;
  for (size_t i = 0; i < N; ++i) out += (i ? ", " : "") + single_quoted(items[i]);
  return out;
}

// "; did you mean 'x'?" for the closest candidate when it is close enough to be a typo, else "".
template <size_t N>
std::string did_you_mean(std::string_view given, const std::array<std::string_view, N>& candidates) {
  const std::string lower = lowercase(given);
  std::string_view best;
  size_t best_distance = std::string::npos;
  for (const auto candidate : candidates) {
    const size_t distance = edit_distance(lower, lowercase(candidate));
    if (distance < best_distance) {
      best_distance = distance;
      best = candidate;
    }
  }
  const size_t allowed = std::max<size_t>(2, std::max(given.size(), best.size()) / 3);
  if (best.empty() || best_distance > allowed) return {};
  return "; did you mean " + single_quoted(best) + "?";
}

// A JSON value and where it sits in the file.
struct Node {
  const json& value;
  std::string path;
};

// Reads the values of one document, failing with its file name and the value's path.
class Reader {
 public:
  explicit Reader(const std::filesystem::path& file) : file_(file.string()), directory_(file.parent_path()) {}

  [[noreturn]] void fail(const std::string& path, const std::string& message) const;

  json parse(std::string_view text) const;

  // --- structure

  template <size_t N>
  void expect_object(const Node& node, const std::array<std::string_view, N>& keys) const {
    if (!node.value.is_object())
      fail(node.path,
           "must be an object with the keys " + quoted_list(keys) + ", got " + type_name(node.value));
    for (const auto& [key, value] : node.value.items()) {
      if (std::find(keys.begin(), keys.end(), key) != keys.end()) continue;
      fail(child_path(node.path, key),
           "unknown key" + did_you_mean(key, keys) + " (allowed: " + quoted_list(keys) + ")");
    }
  }

  std::optional<Node> optional_child(const Node& node, std::string_view key) const;

  Node required_child(const Node& node, std::string_view key, const std::string& what) const;

  const json& array(const Node& node, const std::string& what) const;

  // --- values

  double number(const Node& node, double min, double max) const;

  double positive(const Node& node, double max) const;

  int integer(const Node& node, int min, int max) const;

  bool boolean(const Node& node) const;

  std::string string(const Node& node) const;

  template <size_t N>
  std::array<double, N> numbers(const Node& node, double min, double max) const {
    if (!node.value.is_array() || node.value.size() != N)
      fail(node.path, "must be an array of " + std::to_string(N) + " numbers, got " +
                          (node.value.is_array() ? std::to_string(node.value.size()) + " values"
                                                 : type_name(node.value)));
    std::array<double, N> out{};
    for (size_t i = 0; i < N; ++i) out[i] = number(Node{node.value[i], element_path(node.path, i)}, min, max);
    return out;
  }

  std::array<double, 3> nonzero_vector(const Node& node) const;

  template <size_t N>
  std::string_view choice(const Node& node, const std::array<std::string_view, N>& allowed) const {
    const std::string text = string(node);
    for (const auto option : allowed)
      if (option == text) return option;
    fail(node.path, "unknown value " + single_quoted(text) + did_you_mean(text, allowed) +
                        " (allowed: " + quoted_list(allowed) + ")");
  }

  // A file the description names: relative to the description's directory, and it must exist.
  std::filesystem::path existing_file(const Node& node, std::string_view what) const;

  const std::string& file() const { return file_; }

 private:
  // nlohmann reports a number too large for a double without a position: find the literal.
  std::string number_overflow_message(std::string_view text, const std::string& what) const;

  std::string file_;
  std::filesystem::path directory_;
};

}  // namespace tilesplat::json_reader
