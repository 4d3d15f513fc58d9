#include "tilesplat/version.h"

#include "build_commit.h"  // generated at build time: TILESPLAT_GIT_COMMIT, TILESPLAT_BUILD_TYPE

namespace tilesplat {

const char* version() {
  return TILESPLAT_VERSION_STRING;
}

BuildInfo build_info() {
  return {TILESPLAT_VERSION_STRING, TILESPLAT_GIT_COMMIT, TILESPLAT_BUILD_TYPE};
}

}  // namespace tilesplat
