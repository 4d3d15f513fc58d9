// Small text helpers the apps share: quoting, trimming, joining, number formatting, CSV fields.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "quoting.h"

namespace tilesplat::cli {

// 'text', as the apps and the engine quote a value in a message (text/quoting.h).
using ::tilesplat::single_quoted;
// Without leading and trailing spaces and tabs.
std::string trim(std::string_view text);
std::string join(const std::vector<std::string>& items, std::string_view separator);
// The parts between separators (an empty text gives one empty part).
std::vector<std::string> split(std::string_view text, char separator);
// "1,234,567".
std::string group_thousands(uint64_t value);
// Collapses an exception message to one line.
std::string one_line(std::string_view message);
// Fixed-point number with `decimals` digits.
std::string format_fixed(double value, int decimals);
// The same, with "inf", "-inf" and "nan" for the values that have no digits (a PSNR of identical images).
std::string format_number(double value, int decimals);
// The median of the values (the mean of the middle two for an even count); 0 for none.
double median(std::vector<double> values);
// A CSV field: quoted (quotes doubled) when it holds a comma, quote or line break.
std::string csv_field(const std::string& text);

}  // namespace tilesplat::cli
