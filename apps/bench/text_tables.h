// The tables the bench's curve reports print and write: one list of cells per row, shown padded for the
// console or as Markdown.
#pragma once

#include <string>
#include <vector>

namespace tilesplat::bench {

// Columns padded to their widest cell, two spaces apart, one line per row after the header; the first
// column left-aligned when it holds labels (`label_column`), every other right-aligned.
std::string aligned_table(const std::vector<std::string>& header,
                          const std::vector<std::vector<std::string>>& rows, bool label_column);

// Each row's cells, in the tables' column order: cells(row) for every row.
template <typename Row, typename Cells>
std::vector<std::vector<std::string>> table_rows(const std::vector<Row>& rows, const Cells& cells) {
  std::vector<std::vector<std::string>> out;
  out.reserve(rows.size());
  for (const Row& row : rows) out.push_back(cells(row));
  return out;
}

// A PSNR in dB with two decimals, "inf" for identical images.
std::string psnr_cell(double psnr_db);

// A Markdown table: the header, `separator` (e.g. "|---|---:|"), a line per row.
std::string markdown_table(const std::vector<std::string>& header,
                           const std::vector<std::vector<std::string>>& rows, const std::string& separator);

}  // namespace tilesplat::bench
