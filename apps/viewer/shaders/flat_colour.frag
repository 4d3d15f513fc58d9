#version 460
// Opaque, unlit: each face or line has one colour, so that a test can find its pixels exactly.
layout(location = 0) in vec3 vertex_colour;
layout(location = 0) out vec4 colour;

void main() { colour = vec4(vertex_colour, 1.0); }
