#include "shaders.hpp"

namespace aloft::render::shaders {

std::string glsl_source(const std::string& body, bool gles, const std::string& defines) {
  std::string s = gles ? "#version 300 es\nprecision highp float;\nprecision highp sampler2DShadow;\n"
                       : "#version 330 core\n";
  return s + defines + body;
}

// The fraction of the key light that reaches a fragment (1: fully lit), shared by the lit shader and the
// shadowed-room pass. With SHADOWS undefined it is 1.
const char* const kShadowFunction = R"(
in vec4 v_light_clip;
uniform sampler2DShadow u_shadow_map;
uniform float u_shadow_radius;   // PCF radius, shadow-map texture units

// On the room: four taps on a rotated square; each tap is a hardware 2x2 bilinear comparison, so 16
// depth tests in all.
const vec2 kTaps[4] = vec2[4](vec2(-0.9, 0.35), vec2(0.35, 0.9), vec2(0.9, -0.35), vec2(-0.35, -0.9));

float lit_fraction() {
#ifndef SHADOWS
  return 1.0;
#else
  vec3 p = v_light_clip.xyz / v_light_clip.w * 0.5 + 0.5;
  if (v_light_clip.w <= 0.0 || p.x <= 0.0 || p.x >= 1.0 || p.y <= 0.0 || p.y >= 1.0) return 1.0;
  p.z = min(p.z, 1.0);   // receivers beyond the far plane (the wall) still compare against casters
#ifndef ROOM
  // On the mobile (one piece's shadow on another, small and seen against the piece's own shading) one
  // hardware 2x2 comparison is enough; anti-aliasing shades the mobile several times per pixel on a
  // software rasteriser, so the four taps would cost several times over.
  return texture(u_shadow_map, p);
#else
  // Interleaved gradient noise (Jimenez 2014) turns the pattern per pixel: banding becomes a fine grain
  // that reads as softness, at the cost of one multiply-add and no trigonometry.
  float noise = fract(52.9829189 * fract(dot(gl_FragCoord.xy, vec2(0.06711056, 0.00583715))));
  vec2 axis = vec2(noise * 2.0 - 1.0, 1.0 - abs(noise * 2.0 - 1.0));
  axis = normalize(axis);
  mat2 rot = mat2(axis.x, axis.y, -axis.y, axis.x);
  float sum = 0.0;
  for (int i = 0; i < 4; ++i)
    sum += texture(u_shadow_map, vec3(p.xy + rot * kTaps[i] * u_shadow_radius, p.z));
  return sum * 0.25;
#endif
#endif
}

)";

// Lit surfaces (mobile and room). Positions in the model's frame, u_model to world.
const char* const kLitVertex = R"(
in vec3 a_position;
in vec3 a_normal;
uniform mat4 u_model;
uniform mat4 u_view_proj;
uniform mat4 u_light_view_proj;
out vec3 v_world;
out vec3 v_normal;
out vec4 v_light_clip;
void main() {
  vec4 world = u_model * vec4(a_position, 1.0);
  v_world = world.xyz;
  v_normal = mat3(u_model) * a_normal;   // rigid transforms only: no inverse-transpose needed
  // Normal-offset shadow lookup: a few millimetres off the surface, against self-shadowing grain.
  v_light_clip = u_light_view_proj * (world + vec4(normalize(v_normal) * 0.004, 0.0));
  gl_Position = u_view_proj * world;
}
)";

// Compiled in variants by #define (a software rasteriser such as llvmpipe runs both sides of a branch
// under a mask, so switches are compile-time): SHADOWS (sample the shadow map), ROOM (the floor and
// the wall: matt, darkened in their corner; otherwise the mobile: painted steel with highlights),
// BACKGROUND (the room for the cached background: a second output, o_unlit, is the same surface with
// the key light wholly blocked, i.e. in full shadow; the shadowed-room pass blends the two).
// Follows kShadowFunction.
// One warm key spot light with a soft shadow (percentage-closer filtering over a rotated Poisson disc,
// each tap a hardware 2x2 comparison), a sky/ground hemisphere fill, Blinn-Phong highlights, and a
// darkening near the floor-wall corner. Lit in linear space; written with a gamma of 2.
const char* const kLitFragment = R"(
in vec3 v_world;
in vec3 v_normal;
uniform vec3 u_color;            // linear 0..1 (converted from sRGB on the CPU)
uniform vec3 u_eye;              // world, m
uniform vec3 u_light_pos;        // world, m
uniform vec3 u_light_dir;        // unit, the spot's axis
uniform vec2 u_material;         // specular strength, shininess
uniform float u_highlight;       // 0..2.2: tint towards a warm glow (1: the grabbed component, 1.6: touching)
uniform vec2 u_corner;           // floor height y and wall plane z (m), for the corner darkening
layout(location = 0) out vec4 o_color;
#ifdef BACKGROUND
layout(location = 1) out vec4 o_unlit;
#endif

// The display encoding of a linear colour: a gentle roll-off of highlights, then gamma 2 (sqrt is far
// cheaper than pow). decode() is its inverse (kShadowedRoomFragment).
vec4 encode(vec3 color) {
  color = color / (1.0 + 0.15 * color);
  return vec4(sqrt(clamp(color, 0.0, 1.0)), 1.0);
}

void main() {
  vec3 base = u_color;
  vec3 n = normalize(v_normal);
  vec3 v = normalize(u_eye - v_world);
  if (dot(n, v) < 0.0) n = -n;           // thin sheets seen from behind
  vec3 to_light = u_light_pos - v_world;
  float dist = length(to_light);
  vec3 l = to_light / dist;
  float spot = smoothstep(0.45, 0.97, dot(-l, u_light_dir));   // a gallery spot: a soft pool of light
  float diffuse = max(dot(n, l), 0.0);
  vec3 h = normalize(l + v);
#ifdef ROOM
  float spec = 0.0;
#else
  float spec = u_material.x * pow(max(dot(n, h), 0.0), u_material.y) * step(0.0, dot(n, l));
#endif
  float shadow = lit_fraction();
  vec3 key = vec3(1.0, 0.95, 0.86) * 1.25 * spot * shadow;
  float sky = 0.5 + 0.5 * n.y;
  vec3 ambient = mix(vec3(0.15, 0.14, 0.13), vec3(0.30, 0.31, 0.34), sky);
#ifdef ROOM
  // Light gathers less in the corner where the floor meets the wall.
  float d = min(v_world.y - u_corner.x, v_world.z - u_corner.y);
  float near_corner = clamp(1.0 - d / 0.9, 0.0, 1.0);
  ambient *= 1.0 - 0.45 * near_corner * near_corner;
#endif
  vec3 color = base * (ambient + key * diffuse) + key * spec;
#ifndef ROOM
  color = mix(color, vec3(1.0, 0.62, 0.2), 0.45 * u_highlight);
#endif
  o_color = encode(color);
#ifdef BACKGROUND
  o_unlit = encode(base * ambient);   // key light blocked: what full shadow leaves
#endif
}
)";

// The room inside the shadow's rectangle, from the cached background: the fully lit and the fully
// shadowed (unlit) pictures, blended per pixel by the fraction of the key light that gets through.
// The room's colour is linear in that fraction (no highlights on matt paint), so blending the decoded
// linear colours gives what shading with the shadow would, up to the 8-bit rounding of the two
// pictures. Follows kShadowFunction (compiled with SHADOWS).
const char* const kShadowedRoomFragment = R"(
uniform sampler2D u_lit;     // the background, key light on (display encoded, as o_color)
uniform sampler2D u_unlit;   // the background, key light blocked
layout(location = 0) out vec4 o_color;

// Inverse of the lit shader's encode(): square, then undo the roll-off c / (1 + 0.15 c).
vec3 decode(vec3 e) {
  vec3 g = e * e;
  return g / (1.0 - 0.15 * g);
}

void main() {
  ivec2 pixel = ivec2(gl_FragCoord.xy);
  vec3 lit = decode(texelFetch(u_lit, pixel, 0).rgb);
  vec3 unlit = decode(texelFetch(u_unlit, pixel, 0).rgb);
  vec3 color = mix(unlit, lit, lit_fraction());
  color = color / (1.0 + 0.15 * color);
  o_color = vec4(sqrt(clamp(color, 0.0, 1.0)), 1.0);
}
)";

// The finished picture under the room's own geometry, pixel for pixel: it puts the background (and its
// shadow) into the multisampled buffer, with the room's depth, before the mobile is drawn there.
const char* const kCopyFragment = R"(
uniform sampler2D u_frame;
layout(location = 0) out vec4 o_color;
void main() { o_color = texelFetch(u_frame, ivec2(gl_FragCoord.xy), 0); }
)";

const char* const kDepthVertex = R"(
in vec3 a_position;
uniform mat4 u_model;
uniform mat4 u_light_view_proj;
void main() { gl_Position = u_light_view_proj * u_model * vec4(a_position, 1.0); }
)";

const char* const kDepthFragment = R"(
layout(location = 0) out vec4 o_color;
void main() { o_color = vec4(1.0); }
)";

const char* const kLineVertex = R"(
in vec3 a_position;
uniform mat4 u_view_proj;
void main() { gl_Position = u_view_proj * vec4(a_position, 1.0); }
)";

const char* const kLineFragment = R"(
uniform vec4 u_color;   // sRGB, alpha
layout(location = 0) out vec4 o_color;
void main() { o_color = u_color; }
)";

}  // namespace aloft::render::shaders
