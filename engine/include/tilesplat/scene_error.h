/// @file
/// The error every reader of outside data throws: scenes, cameras, camera paths, scene files.
#pragma once

#include <stdexcept>

#include "tilesplat/export.h"

namespace tilesplat {

/// Thrown for any file that cannot be read as a scene (or as cameras, a camera path, a scene file). what()
/// names the file and the problem.
class TILESPLAT_API SceneError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace tilesplat
