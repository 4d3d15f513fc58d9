// AccuracyModes as text: the names the apps take (--accuracy depth16+sh1) and the reports print.
#include <charconv>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

#include "tilesplat/render_settings.h"

namespace tilesplat {

std::string to_string(Antialiasing mode) {
  switch (mode) {
    case Antialiasing::kClassic: return "classic";
    case Antialiasing::kAntialiased: return "antialiased";
    case Antialiasing::kMip: return "mip";
  }
  return "unknown";
}

std::string to_string(Compositor compositor) {
  switch (compositor) {
    case Compositor::kSorted:
      return "sorted";
    case Compositor::kStochastic:
      return "stochastic";
    case Compositor::kRaster:
      return "raster";
  }
  return "unknown";
}

Compositor parse_compositor(const std::string& name) {
  for (Compositor c : {Compositor::kSorted, Compositor::kStochastic, Compositor::kRaster})
    if (to_string(c) == name) return c;
  throw std::invalid_argument("unknown compositor '" + name + "' (expected sorted, stochastic or raster)");
}

std::string to_string(StochasticSampler sampler) {
  switch (sampler) {
    case StochasticSampler::kHash:
      return "hash";
    case StochasticSampler::kStratified:
      return "stratified";
    case StochasticSampler::kSobol:
      return "sobol";
  }
  return "unknown";
}

StochasticSampler parse_stochastic_sampler(const std::string& name) {
  for (StochasticSampler s :
       {StochasticSampler::kHash, StochasticSampler::kStratified, StochasticSampler::kSobol})
    if (to_string(s) == name) return s;
  throw std::invalid_argument("unknown stochastic sampler '" + name +
                              "' (expected hash, stratified or sobol)");
}

namespace {

[[noreturn]] void bad(const std::string& token, const std::string& why) {
  throw std::invalid_argument("accuracy mode '" + token + "': " + why);
}

// A positive number, or a fraction "1/64".
float parse_value(const std::string& token, const std::string& text) {
  auto number = [&](const std::string& part) {
    double value = 0;
    const auto [end, error] = std::from_chars(part.data(), part.data() + part.size(), value);
    if (error != std::errc() || end != part.data() + part.size() || part.empty())
      bad(token, "'" + text + "' is not a number or a fraction like 1/64");
    return value;
  };
  const size_t slash = text.find('/');
  const double value =
      slash == std::string::npos ? number(text) : number(text.substr(0, slash)) / number(text.substr(slash + 1));
  if (!std::isfinite(value)) bad(token, "'" + text + "' is not finite");
  return float(value);
}

int parse_int(const std::string& token, const std::string& text) {
  int value = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc() || end != text.data() + text.size() || text.empty())
    bad(token, "'" + text + "' is not an integer");
  return value;
}

// Shortest text that reads back as the same float.
std::string format_value(float value) {
  char text[32];
  for (int digits = 1; digits <= 9; ++digits) {
    std::snprintf(text, sizeof(text), "%.*g", digits, double(value));
    if (std::stof(text) == value) break;
  }
  return text;
}

}  // namespace

void validate(const AccuracyModes& m) {
  auto fail = [](const std::string& why) { throw std::invalid_argument("accuracy modes: " + why); };
  if (m.depth_key_bits != 32 && m.depth_key_bits != 24 && m.depth_key_bits != 16)
    fail("depth_key_bits must be 32, 24 or 16, not " + std::to_string(m.depth_key_bits));
  if (m.sh_degree_cap < 0 || m.sh_degree_cap > 3)
    fail("sh_degree_cap must be 0 to 3, not " + std::to_string(m.sh_degree_cap));
  if (!(m.transmittance_cutoff > 0.0f && m.transmittance_cutoff < 1.0f))
    fail("transmittance_cutoff must be in (0, 1), not " + format_value(m.transmittance_cutoff));
  // Above 0.99 no splat could ever be blended: alpha is capped at 0.99.
  if (!(m.alpha_cutoff > 0.0f && m.alpha_cutoff <= 0.99f))
    fail("alpha_cutoff must be in (0, 0.99], not " + format_value(m.alpha_cutoff));
  if (m.resort_window != 0 && (m.resort_window < 2 || m.resort_window > 16))
    fail("resort_window must be 0 (off) or 2 to 16, not " + std::to_string(m.resort_window));
  if (m.sort_depth != AccuracyModes::SortDepth::kView && m.sort_depth != AccuracyModes::SortDepth::kDistance)
    fail("unknown sort depth");
  if (m.extent != AccuracyModes::Extent::kSigma3 && m.extent != AccuracyModes::Extent::kOpacityAware)
    fail("unknown extent");
  if (m.tile_test != AccuracyModes::TileTest::kEllipse && m.tile_test != AccuracyModes::TileTest::kSquare)
    fail("unknown tile test");
}

std::string to_string(const AccuracyModes& m) {
  const AccuracyModes reference;
  std::vector<std::string> parts;
  if (m.depth_key_bits != reference.depth_key_bits) parts.push_back("depth" + std::to_string(m.depth_key_bits));
  if (m.sort_depth == AccuracyModes::SortDepth::kDistance) parts.push_back("radial");
  if (m.extent == AccuracyModes::Extent::kOpacityAware) parts.push_back("opacity-extent");
  if (m.tile_test == AccuracyModes::TileTest::kSquare) parts.push_back("square-tiles");
  if (m.sh_degree_cap != reference.sh_degree_cap) parts.push_back("sh" + std::to_string(m.sh_degree_cap));
  if (m.fp16_sh) parts.push_back("fp16-sh");
  if (m.fp16_covariance) parts.push_back("fp16-cov");
  if (m.transmittance_cutoff != reference.transmittance_cutoff)
    parts.push_back("t-cutoff=" + format_value(m.transmittance_cutoff));
  if (m.alpha_cutoff != reference.alpha_cutoff) parts.push_back("alpha-cutoff=" + format_value(m.alpha_cutoff));
  if (m.resort_window != reference.resort_window) parts.push_back("resort" + std::to_string(m.resort_window));
  if (m.fp16_blend) parts.push_back("fp16-blend");
  if (parts.empty()) return "reference";
  std::string text = parts[0];
  for (size_t i = 1; i < parts.size(); ++i) text += "+" + parts[i];
  return text;
}

AccuracyModes parse_accuracy_modes(const std::string& text) {
  AccuracyModes m;
  if (text.empty()) bad(text, "empty");
  size_t start = 0;
  while (start <= text.size()) {
    const size_t end = std::min(text.find('+', start), text.size());
    const std::string token = text.substr(start, end - start);
    start = end + 1;
    const size_t eq = token.find('=');
    const std::string name = token.substr(0, eq);
    const std::string value = eq == std::string::npos ? "" : token.substr(eq + 1);
    if (token == "reference") {
    } else if (token == "depth32" || token == "depth24" || token == "depth16") {
      m.depth_key_bits = std::stoi(token.substr(5));
    } else if (token == "radial") {
      m.sort_depth = AccuracyModes::SortDepth::kDistance;
    } else if (token == "opacity-extent") {
      m.extent = AccuracyModes::Extent::kOpacityAware;
    } else if (token == "square-tiles") {
      m.tile_test = AccuracyModes::TileTest::kSquare;
    } else if (token.size() == 3 && token.compare(0, 2, "sh") == 0 && token[2] >= '0' && token[2] <= '3') {
      m.sh_degree_cap = token[2] - '0';
    } else if (token == "fp16-sh") {
      m.fp16_sh = true;
    } else if (token == "fp16-cov") {
      m.fp16_covariance = true;
    } else if (token == "fp16-blend") {
      m.fp16_blend = true;
    } else if (name == "t-cutoff" && eq != std::string::npos) {
      m.transmittance_cutoff = parse_value(token, value);
    } else if (name == "alpha-cutoff" && eq != std::string::npos) {
      m.alpha_cutoff = parse_value(token, value);
    } else if (name == "resort" && eq != std::string::npos) {
      m.resort_window = parse_int(token, value);
    } else if (token.compare(0, 6, "resort") == 0 && token.size() > 6) {
      m.resort_window = parse_int(token, token.substr(6));
    } else {
      bad(token,
          "unknown; known: reference, depth24, depth16, radial, opacity-extent, square-tiles, sh0..sh3, "
          "fp16-sh, fp16-cov, t-cutoff=X, alpha-cutoff=X, resortN, fp16-blend");
    }
    if (end == text.size()) break;
  }
  try {
    validate(m);
  } catch (const std::invalid_argument& e) {
    bad(text, e.what());
  }
  return m;
}

}  // namespace tilesplat
