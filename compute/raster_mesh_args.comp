#version 460
// The raster compositor's mesh-stage draw (RasterCompositePass): a VkDrawMeshTasksIndirectCommandEXT
// of one workgroup per RASTER_MESH_SPLATS visible splats (the projection's count), along x up to the
// device's limit and then along y (raster_quads.mesh flattens them back in order).
#extension GL_GOOGLE_include_directive : require
#define TS_RASTER_MESH_ARGS_PUSH
#include "common.glsl"

layout(local_size_x = 1) in;

void main() {
  uint visible = pc.counters.v[COUNTER_VISIBLE];
  uint groups = (visible + RASTER_MESH_SPLATS - 1u) / RASTER_MESH_SPLATS;
  uint x = min(groups, pc.max_groups_x);
  pc.args.v[0] = x;
  pc.args.v[1] = x == 0u ? 0u : (groups + x - 1u) / x;
  pc.args.v[2] = 1u;
}
