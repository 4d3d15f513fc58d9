// PixelRegion's checks and text (tilesplat/render_settings.h), apart from the frame code that renders
// regions, so that what only reads settings (the scene readers, the fuzz harnesses) links without it.
#include <algorithm>
#include <stdexcept>
#include <string>
#include <vector>

#include "tilesplat/render_settings.h"

namespace tilesplat {

void validate(const PixelRegion& region, int image_width, int image_height) {
  if (region.whole()) return;
  auto fail = [&](const std::string& why) {
    throw std::invalid_argument("RenderSettings::region " + to_string(region) + ": " + why);
  };
  if (region.width <= 0 || region.height <= 0) fail("its width and height must be positive");
  if (region.x < 0 || region.y < 0) fail("its first column and row must not be negative");
  if (int64_t(region.x) + region.width > image_width || int64_t(region.y) + region.height > image_height)
    fail("it reaches past the " + std::to_string(image_width) + "x" + std::to_string(image_height) +
         " image");
}

std::string to_string(const PixelRegion& region) {
  if (region.whole()) return "whole";
  return std::to_string(region.x) + "," + std::to_string(region.y) + "," + std::to_string(region.width) +
         "x" + std::to_string(region.height);
}

PixelRegion parse_pixel_region(const std::string& text) {
  if (text == "whole") return {};
  // x,y,WxH or x,y,W,H: four non-negative integers.
  std::vector<std::string> fields;
  size_t start = 0;
  for (size_t at = 0; at <= text.size(); ++at)
    if (at == text.size() || text[at] == ',') {
      fields.push_back(text.substr(start, at - start));
      start = at + 1;
    }
  if (fields.size() == 3) {
    const size_t times = fields[2].find('x');
    if (times != std::string::npos) {
      fields.push_back(fields[2].substr(times + 1));
      fields[2].resize(times);
    }
  }
  auto number = [](const std::string& field) {
    const bool digits = !field.empty() && field.size() <= 9 &&
                        std::all_of(field.begin(), field.end(), [](char c) { return c >= '0' && c <= '9'; });
    return digits ? std::stoi(field) : -1;
  };
  int values[4] = {-1, -1, -1, -1};
  if (fields.size() == 4)
    for (int k = 0; k < 4; ++k) values[k] = number(fields[size_t(k)]);
  if (std::any_of(values, values + 4, [](int v) { return v < 0; }))
    throw std::invalid_argument(
        "region '" + text +
        "': expected x,y,WIDTHxHEIGHT (e.g. 0,540,1920x64) or x,y,WIDTH,HEIGHT in pixels");
  return {values[0], values[1], values[2], values[3]};
}

}  // namespace tilesplat
