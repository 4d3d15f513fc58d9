#version 460
// The raster compositor's fragment stage (RasterCompositePass): the splat's alpha at this pixel centre,
// computed with composite.comp's expression (so each splat's alpha is bit for bit the tile
// compositor's), premultiplied for front-to-back "under" blending: the colour attachment's alpha holds
// 1 - T, and the blend adds src * (1 - dst alpha). Fragments below ALPHA_MIN are discarded; nothing
// stops early, as the hardware blend cannot skip a fragment by what the pixel already holds (the
// reference's raster rule, render_reference with Compositor::kRaster).
//
// TS_RASTER_SURFACE_DEPTH (raster_blend_surface, a host's depth out, HostDepth::write_depth): the
// fragment also reads the colour attachment's alpha, 1 - T before it, which rasterization-order
// attachment access makes exactly what the earlier splats at this pixel blended; the fragment whose
// alpha first lifts 1 - T to pc.surface_alpha writes its depth, every other one +inf, and a MIN blend
// keeps it: composite.comp's threshold rule.
#extension GL_GOOGLE_include_directive : require
#define TS_RASTER_PUSH
#include "common.glsl"

layout(constant_id = 1) const float ALPHA_MIN = 1.0 / 255.0;
layout(constant_id = 2) const float MAX_ALPHA = 0.99;

layout(location = 0) flat in vec4 mean_depth_opacity;
layout(location = 1) flat in vec4 conic_mean_lo_x;
layout(location = 2) flat in vec4 colour_mean_lo_y;

layout(location = 0) out vec4 out_colour;      // (alpha rgb, alpha), blended under
layout(location = 1) out vec4 out_depth_sum;   // (alpha depth, 0, 0, alpha), blended under
layout(location = 2) out float out_count;      // 1, added
#ifdef TS_RASTER_SURFACE_DEPTH
layout(location = 3) out float out_surface;    // the depth where 1 - T reaches surface_alpha, else +inf; MIN
layout(input_attachment_index = 0, set = 0, binding = 0) uniform subpassInput blended;  // location 0's
#endif

void main() {
  // The pixel's offset from the mean as composite.comp forms it: relative to the pixel's tile.
  // The camera's pixel: the attachments start at their first tile's corner (a region's, or the image's).
  uvec2 pixel = uvec2(gl_FragCoord.xy) + first_tile_of(pc.first_tile) * TILE_SIZE;
  uvec2 local = pixel % TILE_SIZE;
  vec2 tile_origin = vec2(pixel - local);
  vec4 mdo = mean_depth_opacity;
  vec2 local_mean = vec2((mdo.x - tile_origin.x) + conic_mean_lo_x.w, (mdo.y - tile_origin.y) + colour_mean_lo_y.w);
  float dx = local_mean.x - (float(local.x) + 0.5);
  float dy = local_mean.y - (float(local.y) + 0.5);
  float k0 = (-0.5 * conic_mean_lo_x.x) * dx * dx;
  float k1 = (-conic_mean_lo_x.y) * dx;
  float power = k0 + dy * (k1 + (-0.5 * conic_mean_lo_x.z) * dy);
  float alpha = min(MAX_ALPHA, mdo.w * exp(power));
  if (alpha < ALPHA_MIN) discard;
  out_colour = vec4(colour_mean_lo_y.rgb * alpha, alpha);
  out_depth_sum = vec4(mdo.z * alpha, 0.0, 0.0, alpha);
  out_count = 1.0;
#ifdef TS_RASTER_SURFACE_DEPTH
  float before = subpassLoad(blended).a;
  float after = before + alpha * (1.0 - before);  // what the "under" blend makes of it
  out_surface = before < pc.surface_alpha && after >= pc.surface_alpha ? mdo.z : uintBitsToFloat(0x7f800000u);
#endif
}
