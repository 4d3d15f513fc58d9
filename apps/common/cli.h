// What tilesplat-render, tilesplat-bench, tilesplat-info and tilesplat-viewer share, in one include:
// the command line (arg_parser.h, common_options.h), loading scenes and cameras (scene_loading.h),
// errors and exit codes (app_run.h), output checks (output_paths.h), provenance, text helpers and
// the process's memory. Text outputs are written with tilesplat::write_file_atomically
// (tilesplat/image.h), as the engine writes its images.
#pragma once

#include "app_run.h"
#include "arg_parser.h"
#include "common_options.h"
#include "output_paths.h"
#include "process_memory.h"
#include "provenance.h"
#include "scene_loading.h"
#include "text.h"
