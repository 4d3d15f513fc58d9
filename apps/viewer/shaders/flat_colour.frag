#version 460
// Opaque, unlit: each face or line has one colour, so that a test can find its pixels exactly. The
// colours are linear light; the picture holds display values, as the splats' colours are
// (docs/colour.md), so the fragment writes their sRGB encoding, as a host's lit meshes would.
layout(location = 0) in vec3 vertex_colour;
layout(location = 0) out vec4 colour;

vec3 srgb_encode(vec3 linear) {
  vec3 c = clamp(linear, 0.0, 1.0);
  return mix(12.92 * c, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, greaterThan(c, vec3(0.0031308)));
}

void main() { colour = vec4(srgb_encode(vertex_colour), 1.0); }
