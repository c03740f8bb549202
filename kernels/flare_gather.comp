#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
// Lens flares for compute-only engines (issue 5 "Compute path"), accumulated by gathering: one
// workgroup per screen tile of GLINT_FLARE_GATHER_ROWS x workgroup pixels (each invocation keeps
// its column's pixels in registers), no atomics on the image or on any global buffer.
// 1. Binning: invocation t takes instance base + t (the count is group_count_x of the indirect
//    arguments, read here, over groups_per_instance() = 1; indices past the buffer are skipped) and
//    appends each of its sprites whose conservative rectangle (glint_flare_bounds) meets the tile
//    to a shared list.
// 2. Sprites: the list is turned into GlintFlareSprite (glint_flare_sprite, the function flare.vert
//    evaluates) in chunks of one per invocation, kept in shared memory.
// 3. Shading: every invocation adds glint_flare_shade (the function flare.frag evaluates) of every
//    listed sprite at each of its pixel centres, in fp32.
// Finally a pixel that received light is read, gains the sum and is written once (alpha kept);
// pixels that received none are not touched (bit-identical). docs/FLARE.md "The two paths" says
// why this replaced a per-sprite splat with a float compare-and-swap per pixel.
layout(local_size_x_id = 0, local_size_y_id = 1) in;

#include "flare_look.glsl"

#ifndef DST_FORMAT
#define DST_FORMAT rgba16f
#endif

layout(std430, binding = 0) readonly buffer Instances { GlintFlareInstance instances[]; };
layout(binding = 1) uniform sampler2D atlas;
layout(std430, binding = 2) readonly buffer Indirect { uint indirect_words[]; };  // GlintFlareIndirect
layout(binding = 3, DST_FORMAT) uniform image2D color;
layout(push_constant) uniform Push { GlintFlarePush pc; };

const uint kMaxThreads = GLINT_FLARE_GATHER_MAX_THREADS;
shared uint s_list_count;
shared uint s_list[kMaxThreads * GLINT_FLARE_SPRITES];  // instance * 16 + slot
shared vec4 s_rect[kMaxThreads];                        // lo.xy, size.xy of the listed sprites
shared vec4 s_rgb_lod[kMaxThreads];
shared uint s_tile[kMaxThreads];

void main() {
  const uint threads = gl_WorkGroupSize.x * gl_WorkGroupSize.y;
  const uint t = gl_LocalInvocationIndex;
  // The tile, and this invocation's column of pixels in it (rows gl_WorkGroupSize.y apart).
  const uvec2 tile0 = gl_WorkGroupID.xy * uvec2(pc.tile_w, pc.tile_h);
  const vec2 tile_lo = vec2(tile0), tile_hi = vec2(tile0 + uvec2(pc.tile_w, pc.tile_h));
  const uvec2 p0 = tile0 + gl_LocalInvocationID.xy;

  uint count = indirect_words[pc.indirect_word] / pc.groups_per_instance;
  count = min(count, uint(instances.length()));

  vec3 sum[GLINT_FLARE_GATHER_ROWS];  // indexed by unrolled loops only, so it stays in registers
  [[unroll]] for (uint r = 0u; r < GLINT_FLARE_GATHER_ROWS; ++r) sum[r] = vec3(0.0);

  for (uint base = 0u; base < count; base += threads) {
    if (t == 0u) s_list_count = 0u;
    barrier();
    // 1. Binning: every sprite of one instance against the tile.
    uint i = base + t;
    if (i < count) {
      GlintFlareInstance inst = instances[i];
      for (uint slot = 0u; slot < GLINT_FLARE_SPRITES; ++slot) {
        vec4 b = glint_flare_bounds(inst, slot, pc);
        if (b.x < tile_hi.x && b.z > tile_lo.x && b.y < tile_hi.y && b.w > tile_lo.y) {
          s_list[atomicAdd(s_list_count, 1u)] = i * 16u + slot;
        }
      }
    }
    barrier();
    const uint listed = s_list_count;  // the same in every invocation
    for (uint e0 = 0u; e0 < listed; e0 += threads) {
      barrier();  // the previous chunk's sprites have been shaded (and every invocation read `listed`)
      // 2. Sprites: one per invocation.
      if (e0 + t < listed) {
        uint packed = s_list[e0 + t];
        GlintFlareSprite s = glint_flare_sprite(instances[packed >> 4u], packed & 15u, pc);
        s_rect[t] = vec4(s.lo, s.size);
        s_rgb_lod[t] = vec4(s.rgb, s.lod);
        s_tile[t] = s.tile;
      }
      barrier();
      // 3. Shading: each listed sprite at each of this invocation's pixel centres.
      uint n = min(threads, listed - e0);
      for (uint k = 0u; k < n; ++k) {
        GlintFlareSprite s;
        s.lo = s_rect[k].xy;
        s.size = s_rect[k].zw;
        s.rgb = s_rgb_lod[k].rgb;
        s.lod = s_rgb_lod[k].w;
        s.tile = s_tile[k];
        if (!(s.size.x > 0.0)) continue;
        // glint_flare_shade's own horizontal test (the same expression), once for the column.
        precise float u = (float(p0.x) + 0.5 - s.lo.x) / s.size.x;
        if (u < 0.0 || u >= 1.0) continue;
        [[unroll]] for (uint r = 0u; r < GLINT_FLARE_GATHER_ROWS; ++r) {
          vec2 pixel = vec2(p0.x, p0.y + r * gl_WorkGroupSize.y) + 0.5;
          sum[r] += glint_flare_shade(s, pixel, atlas).rgb;
        }
      }
    }
    barrier();  // the list is consumed before the next batch resets it
  }

  [[unroll]] for (uint r = 0u; r < GLINT_FLARE_GATHER_ROWS; ++r) {
    uvec2 p = uvec2(p0.x, p0.y + r * gl_WorkGroupSize.y);
    if (sum[r] == vec3(0.0) || p.x >= uint(pc.viewport_w) || p.y >= uint(pc.viewport_h)) continue;
    vec4 c = imageLoad(color, ivec2(p));
    imageStore(color, ivec2(p), vec4(c.rgb + sum[r], c.a));
  }
}
