#version 450
// Shading of the draping scene. Modes (aux.x): 0 lit colour, 1 dress form with reference
// lines, 2 cloth (two-sided, grain lines, optional colour map), 3 unlit colour, 4 floor grid.
layout(location = 0) in vec3 v_pos;
layout(location = 1) in vec3 v_normal;
layout(location = 2) in vec2 v_uv;
layout(location = 3) in vec4 v_color;
layout(location = 4) in vec4 v_aux;

layout(push_constant) uniform PC {
  mat4 view_proj;
  vec4 eye;
  vec4 heights;
  vec4 angles;
  ivec4 flags;
} pc;

layout(location = 0) out vec4 out_color;

// The shading modes a pipeline can meet (bit m = mode m), a specialisation constant: the renderer
// makes one pipeline per set of modes a draw contains, so the code of the other modes is
// removed at pipeline creation. On lavapipe (llvmpipe) divergent branches are not skipped: an
// uber-shader runs every mode's code for every pixel.
layout(constant_id = 0) const int kModes = 31;

const float PI = 3.14159265358979;

// Coverage of a line of half-width hw (in the units of d) with a one-pixel soft edge.
float line_cov(float d, float hw) {
  float w = max(fwidth(d), 1e-6);
  return 1.0 - smoothstep(hw - 0.5 * w, hw + 0.5 * w, abs(d));
}

// Coverage of lines at every multiple of `spacing` of coordinate x; fades out when the lines get
// closer than ~4 pixels so that distant cloth does not shimmer (moire).
float grid_cov(float x, float spacing, float hw) {
  float d = (fract(x / spacing + 0.5) - 0.5) * spacing;
  float w = max(fwidth(x), 1e-6);
  float fade = 1.0 - smoothstep(0.15, 0.3, w / spacing);
  return line_cov(d, max(hw, 0.5 * w)) * fade;
}

float angle_dist(float a, float b) {
  float d = abs(a - b);
  return min(d, 2.0 * PI - d);
}

vec3 ramp_diverging(float s) {  // s in [-1, 1]: blue (compression) - white - red (tension)
  s = clamp(s, -1.0, 1.0);
  return s < 0.0 ? mix(vec3(0.95), vec3(0.10, 0.25, 0.85), -s) : mix(vec3(0.95), vec3(0.85, 0.10, 0.08), s);
}

vec3 ramp_ease(float s) {  // s in [0, 1]: red (tight) - yellow - green - blue (loose)
  s = clamp(s, 0.0, 1.0);
  vec3 c0 = vec3(0.85, 0.10, 0.08), c1 = vec3(0.95, 0.85, 0.20), c2 = vec3(0.20, 0.70, 0.30),
       c3 = vec3(0.15, 0.35, 0.85);
  if (s < 0.33) return mix(c0, c1, s / 0.33);
  if (s < 0.66) return mix(c1, c2, (s - 0.33) / 0.33);
  return mix(c2, c3, (s - 0.66) / 0.34);
}

vec3 lit(vec3 base, vec3 n, vec3 v, float spec) {
  vec3 key = normalize(vec3(0.35, 0.85, 0.55));
  vec3 fill = normalize(vec3(-0.6, 0.3, 0.4));
  float d = max(dot(n, key), 0.0) * 0.75 + max(dot(n, fill), 0.0) * 0.2 + max(dot(n, v), 0.0) * 0.2;
  vec3 h = normalize(key + v);
  float s = spec * pow(max(dot(n, h), 0.0), 40.0);
  return base * (0.18 + d) + vec3(s);
}

vec3 to_srgb(vec3 c) {
  c = clamp(c, 0.0, 1.0);
  return mix(c * 12.92, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(0.0031308, c));
}

void main() {
  int mode = int(v_aux.x + 0.5);
  vec3 v = normalize(pc.eye.xyz - v_pos);
  vec3 n = normalize(v_normal);
  vec3 c = v_color.rgb;

  if (mode == 0 && (kModes & 1) != 0) {
    if (dot(n, v) < 0.0) n = -n;
    c = lit(c, n, v, 0.15);
  } else if (mode == 1 && (kModes & 2) != 0) {
    if (dot(n, v) < 0.0) n = -n;
    vec2 rel = v_pos.xz - v_aux.yz;
    float r = length(rel);
    float theta = atan(rel.x, rel.y);  // 0 at +z (centre front), pi/2 at +x (form's left)
    if (theta < 0.0) theta += 2.0 * PI;
    float hw = pc.heights.w;
    c = lit(c, n, v, 0.25);
    float cf = max(line_cov(r * angle_dist(theta, pc.angles.x), hw),
                   line_cov(r * angle_dist(theta, pc.angles.y), hw));
    float sides = max(line_cov(r * angle_dist(theta, pc.angles.z), hw),
                      line_cov(r * angle_dist(theta, pc.angles.w), hw));
    float horiz = max(line_cov(v_pos.y - pc.heights.x, hw),
                      max(line_cov(v_pos.y - pc.heights.y, hw), line_cov(v_pos.y - pc.heights.z, hw)));
    c = mix(c, vec3(0.75, 0.05, 0.05), cf);
    c = mix(c, vec3(0.05, 0.20, 0.75), sides);
    c = mix(c, vec3(0.08, 0.08, 0.08), horiz);
  } else if (mode == 2 && (kModes & 4) != 0) {
    bool back = dot(n, v) < 0.0;
    if (back) n = -n;
    vec3 base = c;
    if (pc.flags.x == 1) base = ramp_diverging(v_aux.w);
    if (pc.flags.x == 2) base = ramp_ease(v_aux.w);
    if (back) base *= 0.8;
    if (pc.flags.z != 0) {
      float sp = pc.eye.w;
      // Warp threads run along v (lines of constant u); weft threads along u (constant v).
      float warp = grid_cov(v_uv.x, sp, 0.06 * sp);
      float weft = grid_cov(v_uv.y, sp, 0.06 * sp);
      // Every 5th warp line stronger: the straight grain to judge by.
      float grain = grid_cov(v_uv.x, 5.0 * sp, 0.08 * sp);
      base = mix(base, vec3(0.55, 0.12, 0.10), weft * 0.55);
      base = mix(base, vec3(0.10, 0.18, 0.60), warp * 0.55);
      base = mix(base, vec3(0.05, 0.10, 0.45), grain * 0.8);
    }
    c = lit(base, n, v, 0.05);
  } else if (mode == 4 && (kModes & 16) != 0) {
    float minor = max(grid_cov(v_pos.x, 0.1, 0.004), grid_cov(v_pos.z, 0.1, 0.004));
    float major = max(grid_cov(v_pos.x, 1.0, 0.008), grid_cov(v_pos.z, 1.0, 0.008));
    float dist = length(v_pos.xz);
    c = mix(c, vec3(0.30), minor * 0.6);
    c = mix(c, vec3(0.15), major * 0.8);
    c = mix(c, vec3(0.20, 0.21, 0.23), smoothstep(2.0, 3.0, dist));
    c *= 0.5 + 0.5 * max(n.y, 0.0);
  }
  // mode 3: unlit colour as given.
  if (pc.flags.y != 0) c = to_srgb(c);
  out_color = vec4(c, 1.0);
}
