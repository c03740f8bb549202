#version 460
#extension GL_GOOGLE_include_directive : require
// The demo scene: an HDR starfield with brightness from 0.05 to 50 and a sun
// of brightness 10 to 100, generated on the GPU. Each cell of cell_px pixels may hold one star at
// a hashed position; stars are small Gaussians (sigma 0.6 px) so they are not aliased dots.
layout(local_size_x_id = 0, local_size_y_id = 1) in;

layout(binding = 0, DST_FORMAT) uniform writeonly image2D target;

#include "demo_params.h"
layout(push_constant) uniform Push { StarfieldPush p; };

uint hash(uint x) {  // lowbias32 (Wellons)
  x ^= x >> 16; x *= 0x7feb352du; x ^= x >> 15; x *= 0x846ca68bu; x ^= x >> 16;
  return x;
}
float rand01(inout uint state) { state = hash(state); return float(state >> 8) * (1.0 / 16777216.0); }

vec3 star_colour(float t) {  // cool red to hot blue-white
  return mix(vec3(1.0, 0.75, 0.55), vec3(0.7, 0.8, 1.0), t);
}

void main() {
  ivec2 xy = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(xy, ivec2(p.width, p.height)))) return;
  vec2 pos = vec2(xy) + 0.5;
  vec3 c = vec3(0.004, 0.005, 0.012) * (1.0 + pos.y / float(p.height));  // faint sky
  ivec2 cell = xy / p.cell_px;
  // Stars near a cell edge spill into neighbours: look at the 3x3 cells around.
  for (int dy = -1; dy <= 1; ++dy) {
    for (int dx = -1; dx <= 1; ++dx) {
      ivec2 cc = cell + ivec2(dx, dy);
      uint state = hash(uint(cc.x) * 73856093u ^ uint(cc.y) * 19349663u ^ p.variant * 83492791u);
      if (rand01(state) > p.star_probability) continue;
      vec2 centre = (vec2(cc) + vec2(rand01(state), rand01(state))) * float(p.cell_px);
      // Log-uniform brightness: many dim stars, a few bright ones.
      float b = p.min_brightness * pow(p.max_brightness / p.min_brightness, pow(rand01(state), 3.0));
      vec3 col = star_colour(rand01(state));
      vec2 d = pos - centre;
      c += col * b * exp(-dot(d, d) / (2.0 * 0.36));
    }
  }
  // Sun: a disc with limb darkening and a thin corona.
  float r = length(pos - vec2(p.sun_x, p.sun_y)) / p.sun_radius_px;
  if (r < 1.0) {
    c += vec3(1.0, 0.95, 0.85) * p.sun_brightness * (0.6 + 0.4 * sqrt(1.0 - r * r));
  } else {
    c += vec3(1.0, 0.9, 0.7) * 0.5 * exp(-8.0 * (r - 1.0));
  }
  imageStore(target, xy, vec4(c, 1.0));
}
