#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require
// Cull and occlusion grid test of the lens-flare lights (docs/OCCLUSION.md: a grid test on
// the Hi-Z), the first of the four dispatches of the order-preserving compaction (the same
// instance order on every run); built with GLINT_CULL_ONE_GROUP, the whole cull of few lights in
// one workgroup (cull_in_one_group() at the end), and with GLINT_CULL_FROM_DEPTH too, the same
// test read from the depth image by a workgroup per sample, the last of which runs that cull (the
// last main()). One invocation per light, GLINT_CULL_GROUP per workgroup
// (the one-workgroup variant: up to one invocation per sample, the lights chunk after chunk):
// 1. reject disabled lights and lights with a non-finite float field (GLINT_FLARE_DISABLED), then
//    project (Vulkan conventions) and reject w <= 0, non-finite clip coordinates, depth outside
//    [0, 1] and |ndc.xy| > margin (GLINT_FLARE_FRUSTUM);
// 2. grid test: the light's size_px square is cut into N x N cells, each holding one
//    multi-jittered sample (Chiu, Shirley & Wang 1994: distinct x and y sub-positions over all
//    N^2 samples, so an occluder edge sliding across the light flips one sample at a time). A
//    sample is visible when any depth texel under its one-cell footprint is not nearer than the
//    light. It is read at Hi-Z level k = ceil(log2(cell size)), where a footprint touches at most
//    2x2 texels (3x3 on the light's border), each holding the farthest depth of its pixels; the
//    footprints cover the light, so the test is conservative (docs/OCCLUSION.md proves it and
//    derives the error and step bounds). Pixels off screen read the nearest edge pixel.
//    visible_fraction = visible samples / N^2;
// 3. a visible light sets its bit in the workgroup's visibility mask (a shared atomicOr, whose
//    result does not depend on the order of the calls) and stores its pixel centre, fraction and
//    depth in the record buffer; the mask goes to the group buffer. light_cull_scan.comp turns the
//    masks into instance slots by a prefix sum, light_cull_scatter.comp writes the instances, so
//    instance order is light order on every run (no atomic decides a slot).
// The frustum, occluded and disabled counts are summed in shared memory and travel in the group
// record (the one-workgroup variant writes them to the statistics itself); the tile scan adds them to the group buffer's header (integer sums: order-independent)
// and the top scan resets them, in a separate dispatch (no in-shader reset race,
// SaschaWillems/Vulkan #748).
layout(local_size_x_id = 0, local_size_y_id = 1) in;

#include "glint/gpu/flare_types.h"
#include "light_cull_params.h"

layout(binding = 0) uniform texture2D depth_tex;  // level 0
layout(binding = 1) uniform texture2D hiz_tex;    // mip m = Hi-Z level m + 1
// GlintFlareLight[] read as three vec4 per light (48 bytes): three 16-byte loads instead of twelve
// 4-byte ones (the struct's members are 4-byte aligned, so its loads are not merged).
layout(std430, binding = 2) readonly buffer Lights { vec4 light_words[]; };
#ifndef GLINT_CULL_ONE_GROUP
layout(std430, binding = 3) writeonly buffer Records { vec4 records[]; };  // centre.xy, fraction, ndc z
layout(std430, binding = 4) writeonly buffer Results { GlintFlareLightResult results[]; };
#define COMPACT_GROUPS_BINDING 5  // the compaction's group buffer: this writes the masks (x, y)
#define COMPACT_NO_SCAN
#include "compact.glsl"
#else
// GlintFlareInstance[] as integer words (bits stored as they are), as light_cull_scatter.comp.
layout(std430, binding = 3) writeonly buffer Instances { uvec4 instance_words[]; };
layout(std430, binding = 4) writeonly buffer Results { GlintFlareLightResult results[]; };
layout(std430, binding = 5) writeonly buffer Indirect { GlintFlareIndirect indirect; };
layout(std430, binding = 6) writeonly buffer Stats { GlintFlareStats stats; };
// The visible lights of the current chunk, one bit per light of the chunk (at most 1024).
shared uint chunk_mask[32];
// Per light of the chunk: samples that see it; bit 31: the early out (cull_in_one_group() below).
shared uint light_seen[1024];
#ifdef GLINT_CULL_FROM_DEPTH
// The depth-image build (GLINT_CULL_FROM_DEPTH, main() at the end): whether sample t of light i sees
// it, at word i * N^2 + t, and the count of finished workgroups. Binding 1 holds the depth image
// again: this build reads no pyramid.
layout(std430, binding = 7) coherent buffer SampleSeen { uint sample_words[]; };
layout(std430, binding = 8) coherent buffer Finished { uint finished_groups; };
#endif
#define GLINT_CULL_STORES_INSTANCES
#define GLINT_CULL_STORES_ARGUMENTS
#include "light_cull_outputs.glsl"
#endif
layout(push_constant) uniform Push { GlintCullPush pc; };

shared uint group_frustum;
shared uint group_occluded;
shared uint group_disabled;
shared uint group_mask[2];

#include "hiz_read.glsl"

bool light_finite(GlintFlareLight l) {
  return cull_finite(l.position_x) && cull_finite(l.position_y) && cull_finite(l.position_z) &&
         cull_finite(l.intensity) && cull_finite(l.color_r) && cull_finite(l.color_g) && cull_finite(l.color_b) &&
         cull_finite(l.size_px);
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

// Whether every texel any sample's window reads is nearer than the light (depth `zt`), decided from
// at most 2x2 texels of a coarser level: then every sample is occluded and the fraction is 0, as
// the sample loop would find with up to 4 reads per sample (9 on the border). The windows lie in
// the union of the footprints (sample_span's extremes: the first and last samples of a row or
// column), widened here each side against the rounding of the footprint edges; the fine texels
// they touch at level k cover pixels p_lo .. p_hi (the last texel of a level reaches the edge);
// level kc is the first at which that range lies in at most 2 texels per axis. A coarse texel
// holds the farthest depth of its pixels, so a coarse texel nearer than the light means every fine
// texel under it is too: exact for depth without NaN. A NaN level-kc texel compares false (no
// early out); whether a NaN pixel reaches level kc is the pyramid's max / min reduction's choice
// (GLSL.std.450 FMax / FMin may return either operand), as it is for the sample loop's texels
// above level 0. No sample's window then exceeds GLINT_CULL_MAX_WINDOW_TEXELS (which would count
// it visible without reading): kc is at most the pyramid's depth, so where level k is capped there
// (k = levels >= kc) the whole union, and every window, lies in at most 2x2 level-k texels.
bool whole_light_hidden(vec2 origin, float unit, int n, bool regular, int k, ivec2 lsize, float zt, bool reversed) {
  const ivec2 ext = regular ? ivec2(0, 2 * n * n) : ivec2(2 - 2 * n, 2 * n * n + 2 * n - 2);
  // The extreme samples' edges are origin + ext * unit, as sample_window() computes them (precise:
  // a product rounded, then a sum rounded); here the compiler may contract either sum into an FMA
  // (SPIR-V leaves it free): the two forms differ by a few units in the last place of the largest
  // term, and the union is widened by 2^-18 of it (8 units in the last place and more).
  const float a0 = float(ext.x) * unit, a1 = float(ext.y) * unit;
  const vec2 widen = ldexp(abs(origin) + max(abs(a0), abs(a1)), ivec2(-18));
  const ivec2 ux = texel_range(origin.x + a0 - widen.x, origin.x + a1 + widen.x, k, pc.width, lsize.x);
  const ivec2 uy = texel_range(origin.y + a0 - widen.y, origin.y + a1 + widen.y, k, pc.height, lsize.y);
  const ivec2 pixels = ivec2(pc.width, pc.height);
  const ivec2 p_lo = ivec2(ux.x, uy.x) << k;
  const ivec2 p_hi = ivec2(ux.y == lsize.x - 1 ? pixels.x - 1 : ((ux.y + 1) << k) - 1,
                           uy.y == lsize.y - 1 ? pixels.y - 1 : ((uy.y + 1) << k) - 1);
  const int span = max(p_hi.x - p_lo.x, p_hi.y - p_lo.y) + 1;
  int kc = hiz_span_level(span);
  // One level lower where the range happens to lie in 2 texels per axis there (it is aligned; the
  // span rule holds for any placement): finer texels are nearer the light more often.
  if (kc > 0) {
    const ivec2 c1 = max(ivec2(1), pixels >> (kc - 1));
    if (all(lessThanEqual(min(p_hi >> (kc - 1), c1 - 1) - min(p_lo >> (kc - 1), c1 - 1), ivec2(1)))) kc -= 1;
  }
  if (kc > int(pc.levels)) return false;
  const ivec2 csize = max(ivec2(1), pixels >> kc);
  const ivec2 t0 = min(p_lo >> kc, csize - 1), t1 = min(p_hi >> kc, csize - 1);
  const vec4 d = hiz_corners(kc, t0, t1);
  return all(reversed ? greaterThan(d, vec4(zt)) : lessThan(d, vec4(zt)));
}

// The grid test of one light: what every sample of it needs (grid_setup), shared by the whole-light
// early out and the samples.
struct GridTest {
  vec2 origin;    // the light square's top-left corner, pixels
  float unit;     // cell / (2n), the unit of sample_span
  float zt;       // the light's depth moved by the depth bias, compared with the texels
  int n;          // samples per side
  int k;          // the Hi-Z level the samples read
  ivec2 lsize;    // that level's size
  bool regular;   // GLINT_CULL_REGULAR_GRID
  bool reversed;  // GLINT_CULL_REVERSED_Z
};

// The grid test of the size_px square centred at `center` (pixels) for a light at depth `z`.
GridTest grid_setup(vec2 center, float size, float z) {
  GridTest g;
  g.n = int(pc.grid);
  g.regular = (pc.flags & GLINT_CULL_REGULAR_GRID) != 0u;
  const float cell = size / float(g.n);
  g.unit = size / float(2 * g.n * g.n);
  g.k = min(cell <= 1.0 ? 0 : ceil_log2(cell), int(pc.levels));
  g.lsize = max(ivec2(1), ivec2(pc.width, pc.height) >> g.k);
  g.reversed = (pc.flags & GLINT_CULL_REVERSED_Z) != 0u;
  g.zt = g.reversed ? z + pc.depth_bias : z - pc.depth_bias;
  precise const vec2 origin = center - 0.5 * size;  // precise: as sample_window()
  g.origin = origin;
  return g;
}

// Whether the grid test can stop at the whole-light early out (the fraction is then 0).
bool grid_hidden(GridTest g) {
  return g.n > 1 && whole_light_hidden(g.origin, g.unit, g.n, g.regular, g.k, g.lsize, g.zt, g.reversed);
}

// The window of the sample of cell (i, j): the level-k texels [tx.x, tx.y] x [ty.x, ty.y] under its
// footprint, clamped to the level. `precise`: the pyramid cull and the depth-image cull (two
// pipelines) find the same window, whatever either compiler contracts into an FMA.
void sample_window(GridTest g, int i, int j, out ivec2 tx, out ivec2 ty) {
  const ivec2 sx = sample_span(i, j, g.n, g.regular), sy = sample_span(j, i, g.n, g.regular);
  precise const vec2 x_edges = g.origin.x + vec2(sx) * g.unit;
  precise const vec2 y_edges = g.origin.y + vec2(sy) * g.unit;
  tx = texel_range(x_edges.x, x_edges.y, g.k, pc.width, g.lsize.x);
  ty = texel_range(y_edges.x, y_edges.y, g.k, pc.height, g.lsize.y);
}

// Whether the sample of cell (i, j) sees the light: any depth texel under its footprint is not
// nearer than the light (the loop stops at the first such texel; the answer does not depend on
// the order of the reads).
bool sample_seen(GridTest g, int i, int j) {
  ivec2 tx, ty;
  sample_window(g, i, j, tx, ty);
  bool seen = (tx.y - tx.x + 1) * (ty.y - ty.x + 1) > GLINT_CULL_MAX_WINDOW_TEXELS;
  for (int y = ty.x; y <= ty.y && !seen; ++y) {
    for (int x = tx.x; x <= tx.y && !seen; ++x) {
      const float d = fetch_level(g.k, ivec2(x, y));
      // Visible where the stored depth is not nearer than the light.
      seen = g.reversed ? d <= g.zt : d >= g.zt;
    }
  }
  return seen;
}

// Visible fraction of the size_px square centred at `center` (pixels) for a light at depth `z`.
float grid_test(vec2 center, float size, float z) {
  const GridTest g = grid_setup(center, size, z);
  if (grid_hidden(g)) return 0.0;
  int visible = 0;
  for (int j = 0; j < g.n; ++j) {
    for (int i = 0; i < g.n; ++i) visible += sample_seen(g, i, j) ? 1 : 0;
  }
  return float(visible) / float(g.n * g.n);
}

// Cull of light i up to its grid test: GLINT_FLARE_DISABLED or _FRUSTUM, or GLINT_FLARE_VISIBLE for
// a light that goes on to the grid test, with its pixel centre, NDC depth and size in pixels (the
// square the grid covers). `words` are the light's three 16-byte words (position, intensity),
// (colour, size_px), (element, enabled, reserved x2).
uint cull_project(uint i, out vec4 words[3], out vec2 center, out float ndc_z, out float size) {
  words[0] = light_words[3u * i];
  words[1] = light_words[3u * i + 1u];
  words[2] = light_words[3u * i + 2u];
  center = vec2(0.0);
  ndc_z = 0.0;
  size = 1.0;
  GlintFlareLight light;
  light.position_x = words[0].x;
  light.position_y = words[0].y;
  light.position_z = words[0].z;
  light.intensity = words[0].w;
  light.color_r = words[1].x;
  light.color_g = words[1].y;
  light.color_b = words[1].z;
  light.size_px = words[1].w;
  light.element = floatBitsToUint(words[2].x);
  light.enabled = floatBitsToUint(words[2].y);
  light.reserved0 = floatBitsToUint(words[2].z);
  light.reserved1 = floatBitsToUint(words[2].w);
  if (light.enabled == 0u || !light_finite(light)) return GLINT_FLARE_DISABLED;
  const vec4 p = vec4(light.position_x, light.position_y, light.position_z, 1.0);
  const float m[16] = pc.view_proj;
  // precise, the projection and the pixel centre: the depth-image cull projects a light in each of
  // its sample workgroups and again in the last one, and the pyramid cull in its own pipeline; each
  // copy must find the same centre and state (SPIR-V leaves FMA contraction free otherwise).
  precise const vec4 clip = vec4(m[0] * p.x + m[4] * p.y + m[8] * p.z + m[12], m[1] * p.x + m[5] * p.y + m[9] * p.z + m[13],
                                 m[2] * p.x + m[6] * p.y + m[10] * p.z + m[14], m[3] * p.x + m[7] * p.y + m[11] * p.z + m[15]);
  // Overflowing clip coordinates (positions near the float range) are culled on the bits too.
  const bool clip_finite = cull_finite(clip.x) && cull_finite(clip.y) && cull_finite(clip.z) && cull_finite(clip.w);
  if (!clip_finite || !(clip.w > 0.0)) return GLINT_FLARE_FRUSTUM;
  precise const vec3 ndc = clip.xyz / clip.w;
  if (!(cull_finite(ndc.x) && cull_finite(ndc.y) && cull_finite(ndc.z) && abs(ndc.x) <= pc.margin_ndc &&
        abs(ndc.y) <= pc.margin_ndc && ndc.z >= 0.0 && ndc.z <= 1.0)) {
    return GLINT_FLARE_FRUSTUM;
  }
  precise const vec2 pixel_centre = (ndc.xy * 0.5 + 0.5) * vec2(pc.width, pc.height);
  center = pixel_centre;
  ndc_z = ndc.z;
  size = light.size_px >= 1.0 ? min(light.size_px, GLINT_CULL_MAX_SIZE_PX) : 1.0;
  return GLINT_FLARE_VISIBLE;
}

#ifdef GLINT_CULL_FROM_DEPTH
// The samples of light i that see it, as the depth-image workgroups found them: light_seen holds
// them per light of the chunk (cull_in_one_group(); chunks are whole workgroups of lights here).
float samples_fraction(uint i) {
  return float(light_seen[i % (gl_WorkGroupSize.x * gl_WorkGroupSize.y)]) / float(pc.grid * pc.grid);
}
#endif

// Cull and grid test of light i: its state (GLINT_FLARE_VISIBLE, _OCCLUDED, _FRUSTUM or _DISABLED),
// and for a light that reaches the grid test its pixel centre, visible fraction and NDC depth.
uint cull_light(uint i, out vec4 words[3], out vec2 center, out float fraction, out float ndc_z) {
  float size;
  fraction = 0.0;
  const uint state = cull_project(i, words, center, ndc_z, size);
  if (state != GLINT_FLARE_VISIBLE) return state;
#ifdef GLINT_CULL_FROM_DEPTH
  fraction = samples_fraction(i);
#else
  fraction = grid_test(center, size, ndc_z);
#endif
  return fraction > 0.0 ? GLINT_FLARE_VISIBLE : GLINT_FLARE_OCCLUDED;
}

void count_state(uint state) {
  if (state == GLINT_FLARE_FRUSTUM) atomicAdd(group_frustum, 1u);
  if (state == GLINT_FLARE_OCCLUDED) atomicAdd(group_occluded, 1u);
  if (state == GLINT_FLARE_DISABLED) atomicAdd(group_disabled, 1u);
}

#ifndef GLINT_CULL_ONE_GROUP
void main() {
  const uint lid = gl_LocalInvocationIndex;  // < GLINT_CULL_GROUP: the bit of this light in the mask
  if (lid == 0u) {
    group_frustum = 0u;
    group_occluded = 0u;
    group_disabled = 0u;
    group_mask[0] = 0u;
    group_mask[1] = 0u;
  }
  barrier();

  // Every invocation runs to the barrier below.
  const uint i = gl_GlobalInvocationID.x;
  const bool in_range = i < pc.count;
  uint state = GLINT_FLARE_DISABLED;
  vec4 words[3];
  vec2 center;
  float fraction, ndc_z;
  if (in_range) state = cull_light(i, words, center, fraction, ndc_z);
  const bool visible = in_range && state == GLINT_FLARE_VISIBLE;

  if (visible) {
    atomicOr(group_mask[lid >> 5u], 1u << (lid & 31u));
    records[i] = vec4(center, fraction, ndc_z);
  }
  if (in_range) count_state(state);
  barrier();
  if (lid == 0u) {  // the counts go to the header through the tile scan (compact.glsl)
    groups[gl_WorkGroupID.x] =
        uvec4(group_mask[0], group_mask[1], compact_pack_counts(uvec4(group_frustum, group_occluded, group_disabled, 0u)), 0u);
  }
  // Visible lights get their result from the scatter, which knows whether they found a slot.
  if (in_range && !visible && (pc.flags & GLINT_CULL_WRITE_RESULTS) != 0u) {
    GlintFlareLightResult r;
    r.visible_fraction = 0.0;
    r.culled = state;
    results[i] = r;
  }
}
#else
// The whole cull in one workgroup (few lights: light_culler.cpp). The lights go in chunks. When the
// workgroup holds more invocations than lights, each light gets `lanes` of them, which share its
// grid test: lane s tests samples s, s + lanes, ... and adds how many see the light to the light's
// shared count, and one lane runs the whole-light early out (lane n^2 when there is one lane per
// sample and one more, else lane 0 before its samples). So the test of few lights waits on one
// round of texel reads, not on a light's samples one after another. The count is an integer sum,
// so the fraction is the one grid_test() returns. With more than half as many lights as
// invocations (lanes = 1) each invocation tests one light with cull_light(), as the four-dispatch
// path does.
// A visible light's slot is the visible lights before its chunk plus the visible lights below it in
// the chunk's mask, so instances are in light order, as the compaction of the multi-workgroup path
// puts them. Then the indirect arguments and statistics, as light_cull_scan.comp writes them. No
// group buffer, no other dispatch.
const uint kHidden = 0x80000000u;
// 0: one invocation per light whatever the count (light_culler.cpp picks this build on CPU devices
// and for more than half as many lights as invocations): lanes is then the constant 1, so the
// sharing code and light_seen fold away.
layout(constant_id = 2) const uint kShareSamples = 1u;

void cull_in_one_group() {
  const uint lid = gl_LocalInvocationIndex;
  const uint size = gl_WorkGroupSize.x * gl_WorkGroupSize.y;  // at most 1024: 32 mask words
  const uint n2 = pc.grid * pc.grid;
  // Invocations per light: one per sample and one for the early out when the workgroup holds them
  // for every light (the same in every invocation: pc.count is uniform).
#ifdef GLINT_CULL_FROM_DEPTH
  const bool share = false;  // the samples are read already
#else
  const bool share = kShareSamples != 0u;
#endif
  const uint lanes = share ? clamp(size / max(pc.count, 1u), 1u, pc.grid > 1u ? n2 + 1u : 1u) : 1u;
  const uint per_chunk = size / lanes;  // lights per chunk
  const uint words_used = (per_chunk + 31u) / 32u;
  const uint l = lid / lanes, lane = lid % lanes;
  const bool own_hidden_lane = lanes == n2 + 1u;  // lane n2 runs the early out, else lane 0 does
  if (lid == 0u) {
    group_frustum = 0u;
    group_occluded = 0u;
    group_disabled = 0u;
  }
  uint before = 0u;  // visible lights in the earlier chunks (the same in every invocation)
  for (uint c0 = 0u; c0 < pc.count; c0 += per_chunk) {
    if (lid < words_used) chunk_mask[lid] = 0u;
    if (lanes > 1u && lid < per_chunk) light_seen[lid] = 0u;
#ifdef GLINT_CULL_FROM_DEPTH
    // The chunk's sample words, one per invocation and round (all loads in flight together; coherent:
    // other workgroups of this dispatch wrote them), counted per light.
    light_seen[lid] = 0u;  // per_chunk == size: one invocation per light
    barrier();
    const uint chunk_samples = min(per_chunk, pc.count - c0) * n2;
    for (uint j = lid; j < chunk_samples; j += size) {
      if (sample_words[c0 * n2 + j] != 0u) atomicAdd(light_seen[j / n2], 1u);
    }
#endif
    barrier();
    const uint i = c0 + l;
    const bool in_range = l < per_chunk && i < pc.count;
    uint state = GLINT_FLARE_DISABLED;
    vec4 words[3];
    vec2 center;
    float ndc_z, fraction = 0.0;
    if (lanes == 1u) {  // one invocation per light: the four-dispatch path's own test
      if (in_range) state = cull_light(i, words, center, fraction, ndc_z);
    } else {
      float light_size;
      if (in_range) state = cull_project(i, words, center, ndc_z, light_size);
      if (in_range && state == GLINT_FLARE_VISIBLE) {  // the grid test, shared by the light's lanes
        const GridTest g = grid_setup(center, light_size, ndc_z);
        bool hidden = false;
        if (lane == (own_hidden_lane ? n2 : 0u)) {
          hidden = grid_hidden(g);
          if (hidden) atomicOr(light_seen[l], kHidden);
        }
        uint seen = 0u;
        for (uint t = lane; t < n2 && !hidden; t += lanes) {
          seen += sample_seen(g, int(t % pc.grid), int(t / pc.grid)) ? 1u : 0u;
        }
        if (seen > 0u) atomicAdd(light_seen[l], seen);
      }
      barrier();
      // Lane 0 of each light carries it from here.
      if (in_range && lane == 0u && state == GLINT_FLARE_VISIBLE) {
        const uint c = light_seen[l];
        fraction = (c & kHidden) != 0u ? 0.0 : float(c) / float(n2);
        state = fraction > 0.0 ? GLINT_FLARE_VISIBLE : GLINT_FLARE_OCCLUDED;
      }
    }
    const bool leader = in_range && lane == 0u;
    const bool visible = leader && state == GLINT_FLARE_VISIBLE;
    if (visible) atomicOr(chunk_mask[l >> 5u], 1u << (l & 31u));
    if (leader) count_state(state);
    barrier();
    uint below = bitCount(chunk_mask[l >> 5u] & ((1u << (l & 31u)) - 1u));
    uint total = 0u;
    for (uint w = 0u; w < words_used; ++w) {
      const uint c = bitCount(chunk_mask[w]);
      below += w < (l >> 5u) ? c : 0u;
      total += c;
    }
    const uint slot = before + below;
    if (visible && slot < pc.capacity) {
      cull_store_instance(slot, i, vec4(center, fraction, ndc_z), words[0], words[1], floatBitsToUint(words[2].x));
    }
    if (leader && (pc.flags & GLINT_CULL_WRITE_RESULTS) != 0u) {
      GlintFlareLightResult r;
      r.visible_fraction = visible && slot < pc.capacity ? fraction : 0.0;
      r.culled = !visible ? state : slot < pc.capacity ? GLINT_FLARE_VISIBLE : GLINT_FLARE_OVERFLOW;
      results[i] = r;
    }
    before += total;
    barrier();  // the next chunk clears the mask and the counts
  }
  barrier();  // the counts' atomics are complete
  if (lid != 0u) return;
  cull_store_arguments(pc.count, before, group_frustum, group_occluded, group_disabled, pc.capacity, pc.vertex_count,
                       pc.groups_per_instance, pc.max_group_count_x);
}

#ifndef GLINT_CULL_FROM_DEPTH
void main() { cull_in_one_group(); }
#else
// Few lights without a pyramid (light_culler.cpp picks this build when its reads are fewer than
// the pyramid's: docs/OCCLUSION.md, "Few lights from the depth image"). Workgroup w tests sample
// t = w % N^2 of light w / N^2: it finds the sample's window at level k as sample_seen() does and
// reads the depth pixels those level-k texels cover, [c 2^k, (c + 1) 2^k) per texel c, the last
// texel of a level to the image's edge (the fold rule, hiz_read.glsl). A texel holds the farthest
// depth of exactly those pixels, so "some texel is not nearer than the light" is "some pixel is not
// nearer": the same answer as the pyramid's, without building it. A window of more than
// GLINT_CULL_MAX_WINDOW_TEXELS texels counts as seen without reading, as there. The workgroup stores
// its answer, makes it visible (memoryBarrierBuffer) and counts itself finished; the last one
// (Kirk and Hwu's threadFenceReduction pattern, AMD FidelityFX SPD's global counter) resets the
// count for the next cull and runs the one-workgroup cull above, each light's fraction from its
// samples' words: instances in light order, results, arguments and statistics. At least one
// workgroup runs (count 0: the last one writes the empty frame's outputs).
shared uint group_seen;
shared bool group_last;

void main() {
  const uint lid = gl_LocalInvocationIndex;
  const uint size = gl_WorkGroupSize.x * gl_WorkGroupSize.y;
  const uint n2 = pc.grid * pc.grid;
  const uint w = gl_WorkGroupID.x;
  const uint i = w / n2, t = w % n2;
  if (lid == 0u) group_seen = 0u;
  barrier();
  if (i < pc.count) {  // uniform in the workgroup: every invocation projects the same light
    vec4 words[3];
    vec2 center;
    float ndc_z, light_size;
    if (cull_project(i, words, center, ndc_z, light_size) == GLINT_FLARE_VISIBLE) {
      const GridTest g = grid_setup(center, light_size, ndc_z);
      ivec2 tx, ty;
      sample_window(g, int(t % pc.grid), int(t / pc.grid), tx, ty);
      if ((tx.y - tx.x + 1) * (ty.y - ty.x + 1) > GLINT_CULL_MAX_WINDOW_TEXELS) {
        if (lid == 0u) group_seen = 1u;
      } else {
        // The pixels of texels [t0, t1] of level k.
        const ivec2 pixels = ivec2(pc.width, pc.height);
        const ivec2 t0 = ivec2(tx.x, ty.x), t1 = ivec2(tx.y, ty.y);
        const ivec2 p0 = t0 << g.k;
        const ivec2 p1 = mix((t1 + 1) << g.k, pixels, equal(t1, g.lsize - 1));  // exclusive
        const uint span_x = uint(p1.x - p0.x);
        const uint pixel_count = span_x * uint(p1.y - p0.y);
        bool seen = false;
        // Four fetches in flight per invocation and round; past the end an invocation reads the
        // window's last pixel again (a repeated pixel changes no answer). Each invocation stops at
        // its first pixel that sees the light; a workgroup-wide stop (a shared flag and a barrier
        // each round) was slower on the H200 (docs/OCCLUSION.md, "Few lights from the depth image").
        for (uint base = lid; base < pixel_count && !seen; base += 4u * size) {
          float d[4];
          for (uint r = 0u; r < 4u; ++r) {
            const uint q = min(base + r * size, pixel_count - 1u);
            d[r] = texelFetch(depth_tex, p0 + ivec2(q % span_x, q / span_x), 0).r;
          }
          for (uint r = 0u; r < 4u; ++r) seen = seen || (g.reversed ? d[r] <= g.zt : d[r] >= g.zt);
        }
        if (seen) atomicOr(group_seen, 1u);
      }
    }
  }
  barrier();
  if (lid == 0u) {
    sample_words[w] = group_seen;
    memoryBarrierBuffer();
    group_last = atomicAdd(finished_groups, 1u) == max(pc.count * n2, 1u) - 1u;
  }
  barrier();
  if (!group_last) return;
  if (lid == 0u) finished_groups = 0u;
  memoryBarrierBuffer();
  cull_in_one_group();
}
#endif
#endif
