#include "scene/json_reader.h"

#include <cmath>
#include <optional>
#include <set>
#include <sstream>

#include "tilesplat/scene.h"

namespace tilesplat::json_reader {

namespace fs = std::filesystem;

namespace {

// Line and column (both from 1) of the character at 1-based byte `offset`, as nlohmann reports it.
std::pair<size_t, size_t> line_and_column(std::string_view text, size_t offset) {
  const size_t index = std::min(offset > 0 ? offset - 1 : 0, text.size());
  const std::string_view before = text.substr(0, index);
  const size_t line = 1 + size_t(std::count(before.begin(), before.end(), '\n'));
  const size_t line_start = before.rfind('\n');
  const size_t column = line_start == std::string_view::npos ? index + 1 : index - line_start;
  return {line, column};
}

// The explanation of a nlohmann parse error without its "[json.exception...] parse error at ...: " prefix.
std::string parse_explanation(const std::string& what) {
  const size_t start = what.find("parse error");
  if (start == std::string::npos) return what;
  const size_t colon = what.find(": ", start);
  return colon == std::string::npos ? what : what.substr(colon + 2);
}

// Tracks the JSON path during parsing, to report duplicate keys (which nlohmann would silently
// resolve to the last one: a mistake the author should hear about).
class DuplicateKeyCheck {
 public:
  // Returns the path of a duplicated key, or nothing.
  std::optional<std::string> on_event(json::parse_event_t event, const json& parsed) {
    switch (event) {
      case json::parse_event_t::object_start:
      case json::parse_event_t::array_start:
        frames_.push_back({event == json::parse_event_t::array_start, 0, next_path(), {}, {}});
        return std::nullopt;
      case json::parse_event_t::object_end:
      case json::parse_event_t::array_end:
        if (!frames_.empty()) frames_.pop_back();
        return std::nullopt;
      case json::parse_event_t::key: {
        Frame& frame = frames_.back();
        frame.key = parsed.get<std::string>();
        if (!frame.keys.insert(frame.key).second) return child_path(frame.path, frame.key);
        return std::nullopt;
      }
      case json::parse_event_t::value:
        next_path();
        return std::nullopt;
    }
    return std::nullopt;
  }

 private:
  struct Frame {
    bool array = false;
    size_t next_index = 0;
    std::string path;
    std::set<std::string> keys;
    std::string key;
  };

  // The path of the value that starts now (advancing the enclosing array's index).
  std::string next_path() {
    if (frames_.empty()) return {};
    Frame& frame = frames_.back();
    if (frame.array) return element_path(frame.path, frame.next_index++);
    return child_path(frame.path, frame.key);
  }

  std::vector<Frame> frames_;
};

}  // namespace

std::string format_number(double value) {
  std::ostringstream out;
  out.precision(10);
  out << value;
  return out.str();
}

std::string child_path(const std::string& parent, std::string_view key) {
  return parent.empty() ? std::string(key) : parent + "." + std::string(key);
}

std::string element_path(const std::string& parent, size_t index) {
  return parent + "[" + std::to_string(index) + "]";
}

std::string lowercase(std::string_view text) {
  std::string out(text);
  for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

size_t edit_distance(std::string_view a, std::string_view b) {
  std::vector<size_t> previous(b.size() + 1), current(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) previous[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    current[0] = i;
    for (size_t j = 1; j <= b.size(); ++j)
      current[j] = std::min({previous[j] + 1, current[j - 1] + 1, previous[j - 1] + (a[i - 1] != b[j - 1])});
    std::swap(previous, current);
  }
  return previous[b.size()];
}

std::string type_name(const json& value) {
  switch (value.type()) {
    case json::value_t::object:
      return "an object";
    case json::value_t::array:
      return "an array";
    case json::value_t::string:
      return "a string";
    case json::value_t::boolean:
      return value.get<bool>() ? "true" : "false";
    case json::value_t::null:
      return "null";
    case json::value_t::number_integer:
    case json::value_t::number_unsigned:
    case json::value_t::number_float:
      return format_number(value.get<double>());
    default:
      return "an unsupported value";
  }
}

void Reader::fail(const std::string& path, const std::string& message) const {
  throw SceneError(file_ + ": " + (path.empty() ? std::string("top level") : path) + ": " + message);
}

json Reader::parse(std::string_view text) const {
  DuplicateKeyCheck duplicates;
  std::optional<std::string> duplicate;
  json document;
  try {
    document = json::parse(text.begin(), text.end(), [&](int, json::parse_event_t event, json& parsed) {
      if (!duplicate) duplicate = duplicates.on_event(event, parsed);
      return true;
    });
  } catch (const json::parse_error& error) {
    const auto [line, column] = line_and_column(text, error.byte);
    throw SceneError(file_ + ": line " + std::to_string(line) + ", column " + std::to_string(column) +
                     ": malformed JSON: " + parse_explanation(error.what()));
  } catch (const json::out_of_range& error) {
    throw SceneError(number_overflow_message(text, error.what()));
  }
  if (duplicate)
    fail(*duplicate, "duplicate key: the object has it twice and only one can count; remove the other");
  return document;
}

std::optional<Node> Reader::optional_child(const Node& node, std::string_view key) const {
  const auto it = node.value.find(std::string(key));
  if (it == node.value.end()) return std::nullopt;
  return Node{*it, child_path(node.path, key)};
}

Node Reader::required_child(const Node& node, std::string_view key, const std::string& what) const {
  auto child = optional_child(node, key);
  if (!child) fail(node.path, "missing " + single_quoted(key) + ": " + what);
  return *child;
}

const json& Reader::array(const Node& node, const std::string& what) const {
  if (!node.value.is_array()) fail(node.path, "must be " + what + ", got " + type_name(node.value));
  return node.value;
}

double Reader::number(const Node& node, double min, double max) const {
  const std::string range = "from " + format_number(min) + " to " + format_number(max);
  if (!node.value.is_number())
    fail(node.path, "must be a number " + range + ", got " + type_name(node.value));
  const double value = node.value.get<double>();
  if (!(value >= min && value <= max)) fail(node.path, "must be " + range + ", got " + format_number(value));
  return value;
}

double Reader::positive(const Node& node, double max) const {
  const std::string range = "greater than 0 and at most " + format_number(max);
  if (!node.value.is_number())
    fail(node.path, "must be a number " + range + ", got " + type_name(node.value));
  const double value = node.value.get<double>();
  if (!(value > 0 && value <= max)) fail(node.path, "must be " + range + ", got " + format_number(value));
  return value;
}

int Reader::integer(const Node& node, int min, int max) const {
  const std::string range = "from " + std::to_string(min) + " to " + std::to_string(max);
  // 1920.0 is as good as 1920: some writers store every number as a float.
  const bool integral =
      node.value.is_number() && std::floor(node.value.get<double>()) == node.value.get<double>();
  if (!integral) fail(node.path, "must be an integer " + range + ", got " + type_name(node.value));
  const double value = node.value.get<double>();
  if (!(value >= min && value <= max)) fail(node.path, "must be " + range + ", got " + format_number(value));
  return static_cast<int>(value);
}

bool Reader::boolean(const Node& node) const {
  if (!node.value.is_boolean()) fail(node.path, "must be true or false, got " + type_name(node.value));
  return node.value.get<bool>();
}

std::string Reader::string(const Node& node) const {
  if (!node.value.is_string()) fail(node.path, "must be a string, got " + type_name(node.value));
  return node.value.get<std::string>();
}

std::array<double, 3> Reader::nonzero_vector(const Node& node) const {
  const auto v = numbers<3>(node, -kMaxCoordinate, kMaxCoordinate);
  if (!(std::hypot(v[0], v[1], v[2]) > 1e-12)) fail(node.path, "must not be the zero vector");
  return v;
}

fs::path Reader::existing_file(const Node& node, std::string_view what) const {
  const std::string text = string(node);
  if (text.empty()) fail(node.path, "must name " + std::string(what) + ", got an empty string");
  const fs::path resolved = (directory_ / fs::path(text)).lexically_normal();
  std::error_code error;
  const auto status = fs::status(resolved, error);
  const std::string named = single_quoted(resolved.string());
  if (!fs::exists(status)) fail(node.path, std::string(what) + " " + named + " does not exist");
  if (fs::is_directory(status)) fail(node.path, named + " is a directory, not " + std::string(what));
  return resolved;
}

std::string Reader::number_overflow_message(std::string_view text, const std::string& what) const {
  const size_t open = what.find('\'');
  const size_t close = what.rfind('\'');
  if (open == std::string::npos || close <= open) return file_ + ": malformed JSON: " + what;
  const std::string literal = what.substr(open + 1, close - open - 1);
  std::string where;
  if (const size_t at = text.find(literal); at != std::string_view::npos) {
    const auto [line, column] = line_and_column(text, at + 1);
    where = ": line " + std::to_string(line) + ", column " + std::to_string(column);
  }
  return file_ + where + ": the number " + literal + " is too large for a 64-bit float";
}

}  // namespace tilesplat::json_reader
