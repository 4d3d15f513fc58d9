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

// A PSNR in dB with two decimals, "inf" for identical images.
std::string psnr_cell(double psnr_db);

// A Markdown table: the header, `separator` (e.g. "|---|---:|"), a line per row.
std::string markdown_table(const std::vector<std::string>& header,
                           const std::vector<std::vector<std::string>>& rows, const std::string& separator);

}  // namespace tilesplat::bench
