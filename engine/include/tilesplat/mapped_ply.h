/// @file
/// MappedPly: the earlier name of SceneInParts (tilesplat/scene_in_parts.h), from when it read binary PLYs
/// only. Code written for it keeps compiling; SceneInParts::open now opens an SPZ and a SOG too.
#pragma once

#include "tilesplat/scene_in_parts.h"

namespace tilesplat {

/// SceneInParts, by its earlier name.
using MappedPly = SceneInParts;

}  // namespace tilesplat
