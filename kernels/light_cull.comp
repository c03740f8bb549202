#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require
#ifdef GLINT_CULL_BALLOT
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_ballot : require
#endif
// Cull, occlusion grid test and compaction of the lens-flare lights in one dispatch (issue 5; seed
// 004 "Method 4", grid test on the Hi-Z of "Method 3"). One invocation per light:
// 1. project (Vulkan conventions); reject disabled lights, w <= 0, depth outside [0, 1] and
//    |ndc.xy| > margin;
// 2. grid test: the light's size_px square is cut into N x N cells, each holding one
//    multi-jittered sample (Chiu, Shirley & Wang 1994: distinct x and y sub-positions over all
//    N^2 samples, so an occluder edge sliding across the light flips one sample at a time). A
//    sample is visible when any depth texel under its one-cell footprint is not nearer than the
//    light. It is read at Hi-Z level k = ceil(log2(cell size)), where a footprint touches at most
//    2x2 texels (3x3 on the light's border), each holding the farthest depth of its pixels; the
//    footprints cover the light, so the test is conservative (docs/OCCLUSION.md proves it and
//    derives the error and step bounds). Pixels off screen read the nearest edge pixel.
//    visible_fraction = visible samples / N^2;
// 3. compaction: visible lights are appended to the instance buffer, with one atomic per subgroup
//    (ballot + exclusive bit count, Wihlidal GDC 2016) or, without subgroup ballot, one per
//    workgroup (shared-memory counter). Slots at or beyond the capacity are never written.
// Counters are reset by light_cull_finalize.comp, a separate dispatch (no in-shader reset race,
// SaschaWillems/Vulkan #748).
layout(local_size_x_id = 0, local_size_y_id = 1) in;

#include "flare_types.h"
#include "occlusion.h"

layout(binding = 0) uniform texture2D depth_tex;  // level 0
layout(binding = 1) uniform texture2D hiz_tex;    // mip m = Hi-Z level m + 1
layout(std430, binding = 2) readonly buffer Lights { GlintFlareLight lights[]; };
layout(std430, binding = 3) writeonly buffer Instances { GlintFlareInstance instances[]; };
layout(std430, binding = 4) writeonly buffer Results { GlintFlareLightResult results[]; };
layout(std430, binding = 5) buffer Counters { uint counters[]; };
layout(push_constant) uniform Push { GlintCullPush pc; };

shared uint group_frustum;
shared uint group_occluded;
shared uint group_disabled;
#ifndef GLINT_CULL_BALLOT
shared uint group_visible;
shared uint group_base;
#endif

float fetch_level(int k, ivec2 t) {
  return k == 0 ? texelFetch(depth_tex, t, 0).r : texelFetch(hiz_tex, t, k - 1).r;
}

// Smallest k with 2^k >= s (s >= 1), exactly: s = m * 2^e with m in [0.5, 1).
int ceil_log2(float s) {
  int e;
  const float m = frexp(s, e);
  return m == 0.5 ? e - 1 : e;
}

// Texels of level k (size `lsize`) under pixels [lo, hi) of one axis, clamped to the image (clamp
// to edge); `pixels` is the level-0 size of that axis.
ivec2 texel_range(float lo, float hi, int k, int pixels, int lsize) {
  const int p0 = clamp(int(floor(lo)), 0, pixels - 1);
  const int p1 = clamp(int(ceil(hi)) - 1, 0, pixels - 1);
  return ivec2(min(p0 >> k, lsize - 1), min(max(p0, p1) >> k, lsize - 1));
}

// Footprint of the sample of cell (i, j) along one axis, in units of cell / (2n) from the light's
// left (top) edge: [lo, hi). Multi-jittered (Chiu, Shirley & Wang 1994, canonical arrangement):
// the sample of cell (i, j) sits at x = i + (j + 0.5) / n, y = j + (i + 0.5) / n cells, so all n^2
// samples have distinct x and distinct y sub-positions (spaced cell / n). Its footprint is one cell
// wide, centred on the sample; on the light's outer border it reaches (n - 1) / (2n) cell further out
// so that the footprints cover the whole light (docs/OCCLUSION.md proves it). Call with
// (i, j) for x and (j, i) for y. Regular grid (GLINT_CULL_REGULAR_GRID): the cell itself.
ivec2 sample_span(int i, int j, int n, bool regular) {
  if (regular) return ivec2(2 * n * i, 2 * n * (i + 1));
  const int centre = 2 * n * i + 2 * j + 1;
  return ivec2(i == 0 ? 2 * j + 2 - 2 * n : centre - n, i == n - 1 ? 2 * n * n + 2 * j : centre + n);
}

// Visible fraction of the size_px square centred at `center` (pixels) for a light at depth `z`.
float grid_test(vec2 center, float size, float z) {
  const int n = int(pc.grid);
  const bool regular = (pc.flags & GLINT_CULL_REGULAR_GRID) != 0u;
  const float cell = size / float(n);
  const float unit = size / float(2 * n * n);  // cell / (2n), the unit of sample_span
  const int k = min(cell <= 1.0 ? 0 : ceil_log2(cell), int(pc.levels));
  const ivec2 lsize = max(ivec2(1), ivec2(pc.width, pc.height) >> k);
  const bool reversed = (pc.flags & GLINT_CULL_REVERSED_Z) != 0u;
  const float zt = reversed ? z + pc.depth_bias : z - pc.depth_bias;
  const vec2 origin = center - 0.5 * size;
  int visible = 0;
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const ivec2 sx = sample_span(i, j, n, regular), sy = sample_span(j, i, n, regular);
      const ivec2 tx = texel_range(origin.x + float(sx.x) * unit, origin.x + float(sx.y) * unit, k, pc.width, lsize.x);
      const ivec2 ty = texel_range(origin.y + float(sy.x) * unit, origin.y + float(sy.y) * unit, k, pc.height, lsize.y);
      bool seen = (tx.y - tx.x + 1) * (ty.y - ty.x + 1) > GLINT_CULL_MAX_WINDOW_TEXELS;
      for (int y = ty.x; y <= ty.y && !seen; ++y) {
        for (int x = tx.x; x <= tx.y && !seen; ++x) {
          const float d = fetch_level(k, ivec2(x, y));
          // Visible where the stored depth is not nearer than the light.
          seen = reversed ? d <= zt : d >= zt;
        }
      }
      visible += seen ? 1 : 0;
    }
  }
  return float(visible) / float(n * n);
}

void main() {
  const uint lid = gl_LocalInvocationIndex;
  if (lid == 0u) {
    group_frustum = 0u;
    group_occluded = 0u;
    group_disabled = 0u;
#ifndef GLINT_CULL_BALLOT
    group_visible = 0u;
#endif
  }
  barrier();

  // Every invocation runs to the end (subgroup operations and barriers below need them all).
  const uint i = gl_GlobalInvocationID.x;
  const bool in_range = i < pc.count;
  uint state = GLINT_FLARE_DISABLED;
  float fraction = 0.0;
  vec2 center = vec2(0.0);
  float ndc_z = 0.0;
  GlintFlareLight light;
  if (in_range) {
    light = lights[i];
    if (light.enabled != 0u) {
      const vec4 p = vec4(light.position_x, light.position_y, light.position_z, 1.0);
      const float m[16] = pc.view_proj;
      const vec4 clip = vec4(m[0] * p.x + m[4] * p.y + m[8] * p.z + m[12], m[1] * p.x + m[5] * p.y + m[9] * p.z + m[13],
                             m[2] * p.x + m[6] * p.y + m[10] * p.z + m[14], m[3] * p.x + m[7] * p.y + m[11] * p.z + m[15]);
      state = GLINT_FLARE_FRUSTUM;
      if (clip.w > 0.0) {
        const vec3 ndc = clip.xyz / clip.w;
        // Written so that NaN fails every test.
        if (abs(ndc.x) <= pc.margin_ndc && abs(ndc.y) <= pc.margin_ndc && ndc.z >= 0.0 && ndc.z <= 1.0) {
          center = (ndc.xy * 0.5 + 0.5) * vec2(pc.width, pc.height);
          ndc_z = ndc.z;
          const float size = light.size_px >= 1.0 ? min(light.size_px, GLINT_CULL_MAX_SIZE_PX) : 1.0;
          fraction = grid_test(center, size, ndc_z);
          state = fraction > 0.0 ? GLINT_FLARE_VISIBLE : GLINT_FLARE_OCCLUDED;
        }
      }
    }
  }
  const bool visible = in_range && state == GLINT_FLARE_VISIBLE;

  // Compaction: a slot for every visible light.
#ifdef GLINT_CULL_BALLOT
  const uvec4 ballot = subgroupBallot(visible);
  const uint subgroup_count = subgroupBallotBitCount(ballot);
  uint base = 0u;
  if (subgroupElect() && subgroup_count > 0u) base = atomicAdd(counters[GLINT_CULL_COUNTER_VISIBLE], subgroup_count);
  base = subgroupBroadcastFirst(base);
  const uint slot = base + subgroupBallotExclusiveBitCount(ballot);
#else
  const uint local_slot = visible ? atomicAdd(group_visible, 1u) : 0u;
#endif
  if (in_range && state == GLINT_FLARE_FRUSTUM) atomicAdd(group_frustum, 1u);
  if (in_range && state == GLINT_FLARE_OCCLUDED) atomicAdd(group_occluded, 1u);
  if (in_range && state == GLINT_FLARE_DISABLED) atomicAdd(group_disabled, 1u);
  barrier();
#ifndef GLINT_CULL_BALLOT
  if (lid == 0u && group_visible > 0u) group_base = atomicAdd(counters[GLINT_CULL_COUNTER_VISIBLE], group_visible);
#endif
  if (lid == 0u) {
    if (group_frustum > 0u) atomicAdd(counters[GLINT_CULL_COUNTER_FRUSTUM], group_frustum);
    if (group_occluded > 0u) atomicAdd(counters[GLINT_CULL_COUNTER_OCCLUDED], group_occluded);
    if (group_disabled > 0u) atomicAdd(counters[GLINT_CULL_COUNTER_DISABLED], group_disabled);
  }
#ifndef GLINT_CULL_BALLOT
  barrier();
  const uint slot = group_base + local_slot;
#endif

  if (!in_range) return;
  if (visible) {
    if (slot < pc.capacity) {
      GlintFlareInstance inst;
      inst.center_x_px = center.x;
      inst.center_y_px = center.y;
      inst.size_px = light.size_px;
      inst.visible_fraction = fraction;
      inst.color_r = light.color_r;
      inst.color_g = light.color_g;
      inst.color_b = light.color_b;
      inst.intensity = light.intensity;
      inst.light_index = i;
      inst.element = light.element;
      inst.ndc_depth = ndc_z;
      inst.reserved = 0u;
      instances[slot] = inst;
    } else {
      state = GLINT_FLARE_OVERFLOW;
    }
  }
  if ((pc.flags & GLINT_CULL_WRITE_RESULTS) != 0u) {
    GlintFlareLightResult r;
    r.visible_fraction = state == GLINT_FLARE_VISIBLE ? fraction : 0.0;
    r.culled = state;
    results[i] = r;
  }
}
