// How a message names a value it quotes: 'value', in the engine's errors and the apps' alike. Header-only,
// so that the apps (which link the public library, not the engine's internals) share it through the
// internal tilesplat_text target (engine/CMakeLists.txt).
#pragma once

#include <string>
#include <string_view>

namespace tilesplat {

inline std::string single_quoted(std::string_view text) {
  std::string out;
  out.reserve(text.size() + 2);
  out += '\'';
  out += text;
  out += '\'';
  return out;
}

}  // namespace tilesplat
