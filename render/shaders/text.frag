#version 450
// Glyph coverage from the atlas (one channel) times the vertex colour's alpha; the background
// quad (uv < 0) is the vertex colour alone. Alpha-blended over the scene.
layout(location = 0) in vec2 v_uv;
layout(location = 1) in vec4 v_color;

layout(push_constant) uniform PC {
  mat4 mvp;
  ivec4 flags;
} pc;

layout(set = 0, binding = 0) uniform sampler2D atlas;

layout(location = 0) out vec4 out_color;

vec3 to_srgb(vec3 c) {
  c = clamp(c, 0.0, 1.0);
  return mix(c * 12.92, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(0.0031308, c));
}

void main() {
  float cover = v_uv.x < 0.0 ? 1.0 : texture(atlas, v_uv).r;
  vec3 c = v_color.rgb;
  if (pc.flags.y != 0) c = to_srgb(c);
  out_color = vec4(c, v_color.a * cover);
}
