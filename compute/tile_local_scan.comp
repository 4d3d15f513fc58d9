#version 460
// Tile-local sort, step 2: one workgroup scans the bin counts (exclusive) into the bins' starts,
// which the scatter then advances to the bins' ends. Up to 2^16 bins: 64 chunks of the workgroup
// scan, one dispatch where the multi-level prefix sum would take three.
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#define TS_TILE_LOCAL_SCAN_PUSH  // its push constants (shader_io.h)
#include "common.glsl"
#include "workgroup_scan.glsl"
#include "tile_local_bins.glsl"

void main() {
  uint linear = gl_SubgroupID * gl_SubgroupSize + gl_SubgroupInvocationID;
  uint running = 0;
  for (uint chunk = 0; chunk < pc.bin_count; chunk += SCAN_BLOCK) {
    uint base = chunk + linear * SCAN_ITEMS;
    uint v[SCAN_ITEMS];
    uint thread_sum = 0;
    for (uint k = 0; k < SCAN_ITEMS; ++k) {
      v[k] = base + k < pc.bin_count ? pc.bins.v[BINS_COUNTS + base + k] : 0u;
      thread_sum += v[k];
    }
    uint chunk_total;
    uint prefix = running + workgroup_exclusive_scan(thread_sum, chunk_total);
    for (uint k = 0; k < SCAN_ITEMS; ++k) {
      if (base + k < pc.bin_count) pc.bins.v[BINS_COUNTS + pc.bin_count + base + k] = prefix;
      prefix += v[k];
    }
    running += chunk_total;
    barrier();  // the scan's shared memory is reused by the next chunk
  }
}
