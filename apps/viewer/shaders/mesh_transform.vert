#version 460
// The viewer's mesh (the box and the ground grid): world-space vertices with a colour each, through
// the camera's clip-from-world matrix (Vulkan clip space, depth 0 at the near plane, 1 at the far).
layout(location = 0) in vec3 position;
layout(location = 1) in vec3 colour;
layout(location = 0) out vec3 vertex_colour;

layout(push_constant) uniform Push {
  mat4 clip_from_world;
}
pc;

void main() {
  gl_Position = pc.clip_from_world * vec4(position, 1.0);
  vertex_colour = colour;
}
