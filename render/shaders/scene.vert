#version 450
// One vertex format for every lit or unlit triangle of the scene (world-space geometry built on
// the CPU; see render/geometry.hpp). aux = (mode, section centre x, section centre z, scalar).
layout(location = 0) in vec3 in_pos;
layout(location = 1) in vec3 in_normal;
layout(location = 2) in vec2 in_uv;
layout(location = 3) in vec4 in_color;
layout(location = 4) in vec4 in_aux;

layout(push_constant) uniform PC {
  mat4 view_proj;
  vec4 eye;      // xyz eye position (m), w grain line spacing (m)
  vec4 heights;  // waist, hip, bust heights (m), w line half-width (m)
  vec4 angles;   // centre front, centre back, left side, right side (rad)
  ivec4 flags;   // x colour map (0 none, 1 strain, 2 ease), y encode sRGB in shader, z grain
} pc;

layout(location = 0) out vec3 v_pos;
layout(location = 1) out vec3 v_normal;
layout(location = 2) out vec2 v_uv;
layout(location = 3) out vec4 v_color;
layout(location = 4) out vec4 v_aux;

void main() {
  v_pos = in_pos;
  v_normal = in_normal;
  v_uv = in_uv;
  v_color = in_color;
  v_aux = in_aux;
  gl_Position = pc.view_proj * vec4(in_pos, 1.0);
}
