/// @file
/// TILESPLAT_API marks what libtilesplat exports. The library is built with hidden symbol visibility,
/// so that a shared libtilesplat.so exports the public API of these headers and nothing else.
#pragma once

/// @def TILESPLAT_API
/// Marks a declaration as part of libtilesplat's exported interface (default symbol visibility).
#if defined(_WIN32)
#if defined(TILESPLAT_BUILDING_SHARED)
#define TILESPLAT_API __declspec(dllexport)
#elif defined(TILESPLAT_SHARED)
#define TILESPLAT_API __declspec(dllimport)
#else
#define TILESPLAT_API
#endif
#else
#define TILESPLAT_API __attribute__((visibility("default")))
#endif
