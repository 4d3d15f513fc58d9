#version 460
// Sample accumulate (RenderSettings::accumulate_samples): a lens or shutter sample frame added to the
// sums of the samples rendered before it, and the frame's outputs replaced by the mean of them all, as the
// host's LinearFrameMean makes it: colours in linear light (A * decode(C / A), or decode(C) for a frame over
// a background), alpha the mean alpha, depth the alpha-weighted mean depth, splat counts the rounded mean.
// The sums (of linear colour, their running mean) alternate between two halves: half samples_before % 2
// is read and the other written, so that a frame that re-runs (a retry) adds its sample once. Finite
// frames give finite means (FLOAT_MAX below). One invocation per pixel.
#extension GL_GOOGLE_include_directive : require
#define TS_SAMPLE_ACCUMULATE_PUSH  // its push constants (shader_io.h)
#include "common.glsl"

layout(local_size_x = 256) in;

// IEC 61966-2-1, as engine/src/image/colour.cpp (odd in the sign).
float srgb_to_linear(float encoded) {
  float m = abs(encoded);
  float linear = m <= 0.04045 ? m / 12.92 : pow((m + 0.055) / 1.055, 2.4);
  return encoded < 0.0 ? -linear : linear;
}
float linear_to_srgb(float linear) {
  float m = abs(linear);
  float encoded = m <= 0.0031308 ? 12.92 * m : 1.055 * pow(m, 1.0 / 2.4) - 0.055;
  return linear < 0.0 ? -encoded : encoded;
}

// The largest finite float. A colour's linear value past it (1e20 decodes to about 1e47) becomes it with
// its sign, and is counted (COUNTER_SATURATED_MEAN): finite samples give a finite mean, as the host's
// LinearFrameMean gives (docs/colour.md, "Saturation").
const float FLOAT_MAX = 3.40282347e38;  // FLT_MAX: glslang rounds the literal to it exactly

vec3 saturated(vec3 v, inout bvec3 past) {
  bvec3 over = greaterThan(abs(v), vec3(FLOAT_MAX));
  past = bvec3(uvec3(past) | uvec3(over));
  return clamp(v, vec3(-FLOAT_MAX), vec3(FLOAT_MAX));
}

// A premultiplied pixel's colour through the transfer function: divided by its coverage first (unless
// opaque, or without partial coverage), multiplied again after.
vec3 transfer(vec3 rgb, float alpha, bool to_linear, inout bvec3 past) {
  bool divide = pc.opaque == 0u && alpha > 0.0 && alpha < 1.0;
  vec3 c = divide ? saturated(rgb / alpha, past) : rgb;
  vec3 t = to_linear ? vec3(srgb_to_linear(c.r), srgb_to_linear(c.g), srgb_to_linear(c.b))
                     : vec3(linear_to_srgb(c.r), linear_to_srgb(c.g), linear_to_srgb(c.b));
  return saturated(divide ? alpha * t : t, past);
}

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= pc.pixels) return;
  vec4 c = pc.rgba.v[i];
  bvec3 past = bvec3(false);
  vec4 sample_value = vec4(transfer(c.rgb, c.a, true, past), c.a);
  vec4 extra = vec4(pc.write_depth != 0u ? c.a * pc.depth.v[i] : 0.0,
                    pc.write_count != 0u ? float(pc.count.v[i]) : 0.0, 0.0, 0.0);
  uint read_half = (pc.samples_before & 1u) * 2u * pc.pixels;
  uint write_half = 2u * pc.pixels - read_half;
  float samples = float(pc.samples_before + 1u);
  // The linear colours are kept as their running mean, whose terms stay within float's range however
  // large the samples are (a sum of them would overflow); alpha, alpha * depth and the counts as sums.
  vec4 kept = sample_value;
  if (pc.samples_before > 0u) {
    vec4 before = pc.sums.v[read_half + 2u * i];
    kept.rgb = saturated(before.rgb * (float(pc.samples_before) / samples) + sample_value.rgb / samples, past);
    kept.a = before.a + sample_value.a;
    extra += pc.sums.v[read_half + 2u * i + 1u];
  }
  pc.sums.v[write_half + 2u * i] = kept;
  pc.sums.v[write_half + 2u * i + 1u] = extra;

  float mean_alpha = kept.a / samples;
  pc.rgba.v[i] = vec4(transfer(kept.rgb, mean_alpha, false, past), mean_alpha);
  if (pc.write_depth != 0u) pc.depth.v[i] = kept.a > 0.0 ? extra.x / kept.a : 0.0;
  if (pc.write_count != 0u) pc.count.v[i] = uint(floor(extra.y / samples + 0.5));
  uvec3 counted = uvec3(past);
  uint values = counted.x + counted.y + counted.z;
  if (values > 0u) atomicAdd(pc.counters.v[COUNTER_SATURATED_MEAN], values);
}
