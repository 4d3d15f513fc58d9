#include "provenance.h"

#include <algorithm>

#include "text.h"
#include "tilesplat/version.h"

namespace tilesplat::cli {

std::string command_line(std::string_view program, int argc, const char* const* argv) {
  std::string command(program);
  for (int i = 1; i < argc; ++i) {
    const std::string_view argument = argv[i];
    command += ' ';
    if (!argument.empty() && argument.find_first_of(" \t\n'\"\\$`;&|<>()*?") == std::string_view::npos) {
      command += argument;
      continue;
    }
    command += '\'';
    for (const char c : argument) {
      if (c == '\'')
        command += "'\\''";
      else
        command += c;
    }
    command += '\'';
  }
  return command;
}

std::string with_provenance_columns(const std::string& csv, const std::string& command) {
  const BuildInfo build = build_info();
  const std::string header = ",tilesplat_version,tilesplat_commit,build_type,command";
  std::string values;
  for (const std::string& field : {csv_field(build.version), csv_field(build.git_commit),
                                   csv_field(build.build_type), csv_field(command)})
    values += "," + field;
  std::string out;
  out.reserve(csv.size() + 64 * size_t(std::count(csv.begin(), csv.end(), '\n')));
  bool quoted = false, first_record = true;
  for (size_t i = 0; i < csv.size(); ++i) {
    const char c = csv[i];
    if (c == '"') quoted = !quoted;  // a doubled quote inside a field toggles twice
    if (c == '\n' && !quoted) {
      const bool crlf = !out.empty() && out.back() == '\r';
      if (crlf) out.pop_back();
      out += first_record ? header : values;
      if (crlf) out += '\r';
      first_record = false;
    }
    out += c;
  }
  if (!csv.empty() && csv.back() != '\n')
    out += first_record ? header : values;  // a last record without '\n'
  return out;
}

}  // namespace tilesplat::cli
