// Texel access shared by image kernels: clamp-to-edge fetches and exact fp32 bilinear weights
// (no sampler filtering, so results do not depend on a device's sub-texel precision).
#extension GL_EXT_samplerless_texture_functions : require

vec4 fetch_clamped(texture2D t, ivec2 ij, ivec2 size) {
  return texelFetch(t, clamp(ij, ivec2(0), size - 1), 0);
}

// Bilinear at continuous texel-centre position p (docs/BLOOM.md, "Notation").
vec3 bilinear(texture2D t, vec2 p, ivec2 size) {
  vec2 f = floor(p);
  vec2 w = p - f;
  ivec2 i0 = ivec2(f);
  vec3 a = fetch_clamped(t, i0, size).rgb;
  vec3 b = fetch_clamped(t, i0 + ivec2(1, 0), size).rgb;
  vec3 c = fetch_clamped(t, i0 + ivec2(0, 1), size).rgb;
  vec3 d = fetch_clamped(t, i0 + ivec2(1, 1), size).rgb;
  return mix(mix(a, b, w.x), mix(c, d, w.x), w.y);
}

// Position in a source of size `src` that has the same normalized UV as texel `xy` of `dst`.
vec2 map_position(ivec2 xy, ivec2 dst, ivec2 src) {
  return (vec2(xy) + 0.5) * (vec2(src) / vec2(dst)) - 0.5;
}
