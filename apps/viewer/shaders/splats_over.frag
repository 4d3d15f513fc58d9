#version 460
// The splats' premultiplied RGBA (render_to_image, over a black background), one texel a pixel, drawn
// with the blend src + (1 - src.a) * dst over the mesh's colour: the blend docs/embedding.md gives hosts.
layout(set = 0, binding = 0) uniform sampler2D splats;
layout(location = 0) out vec4 colour;

void main() { colour = texelFetch(splats, ivec2(gl_FragCoord.xy), 0); }
