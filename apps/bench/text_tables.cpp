#include "text_tables.h"

#include <algorithm>
#include <cmath>

#include "text.h"

namespace tilesplat::bench {

std::string aligned_table(const std::vector<std::string>& header,
                          const std::vector<std::vector<std::string>>& rows, bool label_column) {
  std::vector<size_t> widths;
  for (const std::string& column : header) widths.push_back(column.size());
  for (const std::vector<std::string>& row : rows)
    for (size_t c = 0; c < row.size() && c < widths.size(); ++c)
      widths[c] = std::max(widths[c], row[c].size());
  const auto format = [&](const std::vector<std::string>& line) {
    std::string out;
    for (size_t c = 0; c < line.size() && c < widths.size(); ++c) {
      const std::string pad(widths[c] - line[c].size(), ' ');
      out += c == 0 && label_column ? line[c] + pad : (c == 0 ? "" : "  ") + pad + line[c];
    }
    return out + "\n";
  };
  std::string out = format(header);
  for (const std::vector<std::string>& row : rows) out += format(row);
  return out;
}

std::string psnr_cell(double psnr_db) {
  return std::isinf(psnr_db) ? "inf" : cli::format_fixed(psnr_db, 2);
}

std::string markdown_table(const std::vector<std::string>& header,
                           const std::vector<std::vector<std::string>>& rows, const std::string& separator) {
  const auto line = [](const std::vector<std::string>& cells) {
    std::string out = "|";
    for (const std::string& cell : cells) out += " " + cell + " |";
    return out + "\n";
  };
  std::string out = line(header) + separator + "\n";
  for (const std::vector<std::string>& row : rows) out += line(row);
  return out;
}

}  // namespace tilesplat::bench
