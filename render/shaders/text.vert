#version 450
// The feedback panel (render/text.hpp): vertices in the panel's plane, placed by the model-view-
// projection of the push constants; uv < 0 marks the solid background.
layout(location = 0) in vec2 in_pos;
layout(location = 1) in vec2 in_uv;
layout(location = 2) in vec4 in_color;

layout(push_constant) uniform PC {
  mat4 mvp;      // panel plane -> Vulkan clip
  ivec4 flags;   // y: encode sRGB in the shader (UNORM targets)
} pc;

layout(location = 0) out vec2 v_uv;
layout(location = 1) out vec4 v_color;

void main() {
  v_uv = in_uv;
  v_color = in_color;
  gl_Position = pc.mvp * vec4(in_pos, 0.0, 1.0);
}
