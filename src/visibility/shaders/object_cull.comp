#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require
#extension GL_EXT_control_flow_attributes : require
#ifdef GLINT_OBJECT_SUBGROUP
// The variants the host picks where the device's subgroups support arithmetic and ballots in compute
// (VkPhysicalDeviceSubgroupProperties); the others count with shared atomics alone.
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#extension GL_KHR_shader_subgroup_ballot : require
#endif
// Frustum and Hi-Z occlusion test of caller objects (world-space spheres or boxes), the first of
// the three dispatches of the object cull (include/glint/object_cull.h, docs/OCCLUSION.md "Object
// culling"). One invocation per object, GLINT_OBJECT_GROUP per workgroup, 2D grid of workgroups.
// 1. Bounds in view space (w = clip w). A sphere is inflated by the fp32 error of its transformed
//    centre; a box becomes its 8 corners, each inflated the same way.
// 2. Frustum (conservative): culled only when wholly beyond the far plane, wholly before the near
//    plane, or wholly outside one side plane (a box: all 8 corners outside the same plane).
//    A bound crossing the near plane is visible without an occlusion test.
// 3. Screen rectangle: a sphere's exact projected bounds, from the two tangent lines through the
//    eye in the (x, w) and (y, w) planes (Mara & McGuire, JCGT 2013, "2D Polyhedral Bounds of a
//    Clipped, Perspective-Projected 3D Sphere"); a box's from its projected corners. Every
//    quantity is widened by a bound on its fp32 error (GLINT_OBJECT_EPS).
// 4. Occlusion: the pixel span of the rectangle picks the Hi-Z level where it covers at most 2x2
//    texels (Haar & Aaltonen, SIGGRAPH 2015; zeux/niagara drawcull.comp); the object is occluded
//    when its nearest depth is behind the farthest depth of every texel under the rectangle.
// 5. Two-phase culling (niagara): phase 1 emits objects whose history (the caller's visibility
//    buffer) is VISIBLE and that pass the frustum test; phase 2 tests every object against the new
//    pyramid, writes its state and emits the visible ones phase 1 did not. Emission is a bit in the
//    workgroup's mask; the ordered compaction (compact.glsl) turns the masks into
//    slots in object order, so the list is the same bits on every run.
// 6. The scan of the masks is the next dispatch (object_cull_scan.comp), then the scatter
//    (object_cull_scatter.comp). Folding the scan into this kernel (the last workgroup of each
//    tile scans it, the last tile the tile totals) was measured slower on the H100
//    (docs/OCCLUSION.md, "Cost"): every workgroup then pays a device-scope barrier and an atomic
//    before it retires.
// 7. A workgroup is 128 objects (two groups of 64; 256 on CPU devices). When it holds both kinds, it sorts them
//    before the test (spheres from the first slot, boxes from the last), so that a subgroup runs
//    one kind's code: only the objects' local indices go through shared memory. A workgroup of
//    one kind tests its objects where they are. Every invocation, sorted or not, then loads the
//    whole record of its slot's object (lines the workgroup has just read, so from cache); the
//    results go back to object order for the writes. Exchanging the records themselves through
//    shared memory held them in registers across the barrier: 56 registers against 32, and on the
//    H200 1.4 us slower at 1 M objects and 21 us at 10 M; reloading only in mixed workgroups was
//    0.1 to 0.2 us and 2.6 us slower than reloading in all (docs/OCCLUSION.md, "Cost"). 256-object workgroups were slower on
//    the H100 (fewer invocations fit its registers), 64-object ones slower on mixed scenes (a
//    subgroup more often holds both kinds): docs/OCCLUSION.md, "Cost".
// GLINT_OBJECT_PHASE1 builds the phase-1 variant, which binds no image (the depth image may be a
// render target while phase 1 runs).
// Cost (docs/OCCLUSION.md, "Cost"): one wave of latency-bound invocations, so the kernel keeps
// few live values and one copy of each expensive step: the record is read as 16-byte loads (its
// second half first, for the kind, then both halves after the sort); spheres
// and boxes only reduce their bound to an NDC rectangle and a nearest depth, and one Hi-Z test
// after the branch serves both (a subgroup holding both kinds fetches once, not once per kind);
// each slope pair takes two reciprocals instead of three divisions; a box's frustum test and depth
// range are closed forms over its centre and half axes, and its corners are projected (one
// reciprocal each, the error widening applied once) only when it reaches the Hi-Z test; the
// per-group counts are packed shared atomics, one per subgroup. object_cull_v1.comp is the previous form, kept for the
// benchmark's comparison.
layout(local_size_x_id = 0, local_size_y_id = 1) in;

#include "object_cull_params.h"

#ifdef GLINT_OBJECT_PHASE1
#define BINDING_OBJECTS 0
#define BINDING_VISIBILITY 1
#define BINDING_GROUPS 2
#else
#define BINDING_OBJECTS 2
#define BINDING_VISIBILITY 3
#define BINDING_GROUPS 4
layout(binding = 0) uniform texture2D depth_tex;  // level 0
layout(binding = 1) uniform texture2D hiz_tex;    // mip m = Hi-Z level m + 1
#include "hiz_read.glsl"
#endif

// GlintCullObject[] read as two vec4 per object (32 bytes: sphere_or_min, then box_max and kind):
// two 16-byte loads instead of eight 4-byte ones.
layout(std430, binding = BINDING_OBJECTS) readonly buffer Objects { vec4 object_words[]; };
#ifdef GLINT_OBJECT_PHASE1
layout(std430, binding = BINDING_VISIBILITY) readonly buffer Visibility { uint visibility[]; };
#else
layout(std430, binding = BINDING_VISIBILITY) buffer Visibility { uint visibility[]; };
#endif
#define COMPACT_GROUPS_BINDING BINDING_GROUPS  // the compaction's group buffer: this writes the masks (x, y)
#define COMPACT_NO_SCAN                        // and the packed counts (z)
#include "compact.glsl"
layout(push_constant) uniform Push { GlintObjectCullPush pc; };

// A workgroup is kGroups groups of 64 objects (the host picks 128 invocations, which every
// Vulkan device allows; 256 on CPU devices).
const uint kThreads = gl_WorkGroupSize.x;
const uint kGroups = (kThreads + GLINT_OBJECT_GROUP - 1u) / GLINT_OBJECT_GROUP;  // kThreads is a multiple of 64
const uint kNotTested = 0x80000000u;
// The local index of the object in each slot once sorted by kind for the test (main, step 1;
// kNotTested: beyond the count, or not tested in phase 1), and each object's result by local
// index: state | invalid << 2.
shared uint s_who[kThreads];
shared uint s_state[kThreads];
shared uint s_ends[2];  // slots taken: spheres from the front, boxes from the back
shared uint s_mask[2 * kGroups];
shared uint s_counts[kGroups];  // each group's counts, packed as compact_pack_counts packs them

const float kEps = float(GLINT_OBJECT_EPS);

#ifdef GLINT_OBJECT_PHASE1
bool finite_f(float x) { return (floatBitsToUint(x) & 0x7f800000u) != 0x7f800000u; }
#else
bool finite_f(float x) { return cull_finite(x); }
#endif
bool finite3(vec3 v) { return finite_f(v.x) && finite_f(v.y) && finite_f(v.z); }

vec4 row(float r[4]) { return vec4(r[0], r[1], r[2], r[3]); }

// A point in view space: (x, y, w) and a bound on the fp32 error of each coordinate, summed (the
// error vector's length is at most that sum). GLINT_OBJECT_EPS is 64 units in the last place; a
// 4-term dot product errs by at most 4 (Higham, "Accuracy and Stability of Numerical Algorithms",
// 3.1) of its absolute terms' sum.
vec3 to_view(vec3 p, out float err) {
  const vec4 h = vec4(p, 1.0);
  const vec4 vx = row(pc.view_x), vy = row(pc.view_y), vw = row(pc.view_w);
  err = kEps * (dot(abs(vx), abs(h)) + dot(abs(vy), abs(h)) + dot(abs(vw), abs(h)));
  return vec3(dot(vx, h), dot(vy, h), dot(vw, h));
}

// Largest signed distance, over points q of a set, of q to the two side planes of one axis
// (|s * c / w + o| <= 1, i.e. s * c + (1 + o) w >= 0 and -s * c + (1 - o) w >= 0), each widened by
// `r` (the point's inflation) and the fp32 error of the plane evaluation. Callers take the max
// over the set's points; the set is outside a plane when that max is negative. `len` holds the
// normals' lengths (pc.plane_len: per frame, rounded up on the host).
vec2 plane_margin(float c, float w, float r, float s, float o, vec2 len) {
  const vec2 nx = vec2(s, -s), nw = vec2(1.0 + o, 1.0 - o);
  const vec2 d = nx * c + nw * w;
  return d + len * r * (1.0 + kEps) + kEps * (abs(nx * c) + abs(nw * w));
}

// plane_margin's two planes of one axis, largest over the corners of a box given as its centre
// `c` = (c, w) and half axes e0, e1, e2 (each a (c, w) change): the centre's margin plus the sum of
// |margin change| along the half axes (a linear function's largest value over a box), widened by
// the corners' error r and by the rounding of the evaluation (kEps times its terms' absolute
// values, which bound every corner's: |c_j| <= |c| + sum |e_k.x|, likewise w).
vec2 box_margin(vec2 c, vec2 e0, vec2 e1, vec2 e2, float r, float s, float o, vec2 len) {
  const vec2 nx = vec2(s, -s), nw = vec2(1.0 + o, 1.0 - o);
  const vec2 d = nx * c.x + nw * c.y;
  const vec2 spread = abs(nx * e0.x + nw * e0.y) + abs(nx * e1.x + nw * e1.y) + abs(nx * e2.x + nw * e2.y);
  const float tc = abs(c.x) + abs(e0.x) + abs(e1.x) + abs(e2.x), tw = abs(c.y) + abs(e0.y) + abs(e1.y) + abs(e2.y);
  return d + spread + len * r * (1.0 + kEps) + kEps * (abs(nx) * tc + abs(nw) * tw);
}

// The slopes c / w of the two lines through the eye tangent to the disc of centre (c, w) and
// radius r in one axis plane (w > r), widened by their fp32 error (Mara & McGuire 2013, section 3;
// the form of zeux/niagara that divides without cancellation in the numerator's sign).
vec2 sphere_slopes(float c, float w, float r) {
  // The slopes are ratios: c, w and r scaled by one power of two (exact) give the same ones. A
  // bound beyond 2^60 is scaled by 2^-100 first, so that the squares below stay in the fp32 range
  // (c, w < 2^128 become < 2^28; w > r, and r is at least kEps w, stays normal).
  if (max(abs(c), w) > 1152921504606846976.0) {  // 2^60
    const float k = 7.888609052210118e-31;         // 2^-100
    c *= k;
    w *= k;
    r *= k;
  }
  const float t = sqrt(max(c * c + (w - r) * (w + r), 0.0));  // length of the tangent
  // Two reciprocals instead of three divisions: the smaller denominator t w - r |c| (> 0) is the
  // one whose reciprocal is larger. Each reciprocal and product adds a few units in the last place,
  // within the kEps margin the bound is widened by.
  const float tc = t * c, rw = r * w, tw = t * w, rc = r * c;
  const float i_lo = 1.0 / (tw + rc), i_hi = 1.0 / (tw - rc);
  const float i_den = max(i_lo, i_hi);
  // Each factor divided by the denominator on its own: the product of the two numerators (about
  // w^4) and i_den^2 (about w^-4) leave the fp32 range from w = 2^32 on (0 x Inf, a NaN bound).
  const float err = kEps * ((t * abs(c) + rw) * i_den) * ((tw + r * abs(c)) * i_den);
  return vec2((tc - rw) * i_lo - err, (tc + rw) * i_hi + err);
}

// The NDC interval of slopes [m.x, m.y] on one axis (ndc = s * m + o), widened by the rounding of
// that map.
vec2 slopes_to_ndc(vec2 m, float s, float o) {
  const vec2 n = vec2(s * m.x + o, s * m.y + o);
  const float e = kEps * (abs(s) * max(abs(m.x), abs(m.y)) + abs(o) + 1.0);
  return vec2(min(n.x, n.y) - e, max(n.x, n.y) + e);
}

// Nearest depth of a bound whose smallest w is w_min (> 0), moved towards the camera by its
// fp32 error.
float nearest_depth(float w_min, bool reversed) {
  const float q = pc.depth_b / w_min;
  const float z = pc.depth_a + q;
  const float e = kEps * (abs(pc.depth_a) + abs(q));
  return reversed ? z + e : z - e;
}

#ifndef GLINT_OBJECT_PHASE1
// Occlusion of the NDC rectangle [x.x, x.y] x [y.x, y.y] with nearest depth z: VISIBLE or
// OCCLUDED.
uint hiz_test(vec2 x, vec2 y, float z, bool reversed) {
  const ivec2 isize = ivec2(pc.width, pc.height);
  const vec2 size = vec2(isize);
  // Pixels: ndc -1 is the left (top) edge; widened by the rounding of the map.
  const vec2 lo = (vec2(x.x, y.x) * 0.5 + 0.5) * size - kEps * size * (abs(vec2(x.x, y.x)) + 1.0);
  const vec2 hi = (vec2(x.y, y.y) * 0.5 + 0.5) * size + kEps * size * (abs(vec2(x.y, y.y)) + 1.0);
  // Pixel p covers [p, p + 1): the rectangle touches floor(lo) .. ceil(hi) - 1, clamped (clamped
  // before the conversion so that no float outside the int range is converted).
  const vec2 clo = clamp(lo, vec2(0.0), size), chi = clamp(hi, vec2(0.0), size);
  const ivec2 p0 = min(ivec2(floor(clo)), isize - 1);
  const ivec2 p1 = clamp(ivec2(ceil(chi)) - 1, p0, isize - 1);
  const int span = max(p1.x - p0.x, p1.y - p0.y) + 1;
  const int k = min(hiz_span_level(span), int(pc.levels));
  const ivec2 lsize = max(ivec2(1), isize >> k);
  const ivec2 t0 = min(p0 >> k, lsize - 1), t1 = min(p1 >> k, lsize - 1);
  // Visible where the stored (farthest) depth is not nearer than the object.
  if (t1.x - t0.x <= 1 && t1.y - t0.y <= 1) {
    // The usual window (the level was chosen for it): one pattern of 4 independent fetches, the
    // corners of [t0, t1] (a 1-texel side reads its texel twice), compared texel by texel (a NaN
    // texel passes no comparison, as in the loop below).
    const vec4 d = hiz_corners(k, t0, t1);
    const bvec4 v = reversed ? lessThanEqual(d, vec4(z)) : greaterThanEqual(d, vec4(z));
    return any(v) ? GLINT_OBJECT_STATE_VISIBLE : GLINT_OBJECT_STATE_OCCLUDED;
  }
  if ((t1.x - t0.x + 1) * (t1.y - t0.y + 1) > GLINT_OBJECT_MAX_WINDOW) return GLINT_OBJECT_STATE_VISIBLE;
  for (int ty = t0.y; ty <= t1.y; ++ty) {
    for (int tx = t0.x; tx <= t1.x; ++tx) {
      const float d = fetch_level(k, ivec2(tx, ty));
      // Visible where the stored (farthest) depth is not nearer than the object.
      if (reversed ? d <= z : d >= z) return GLINT_OBJECT_STATE_VISIBLE;
    }
  }
  return GLINT_OBJECT_STATE_OCCLUDED;
}
#endif

// The state of one object; `invalid` is set for malformed bounds (counted visible). NONE means
// "in the frustum, in front of the near plane": the caller runs hiz_test on the NDC rectangle
// `rect` (x0, x1, y0, y1) with nearest depth `z`, so the test is one copy of code for both kinds.
uint test_object(vec4 w0, vec4 w1, bool frustum_only, out bool invalid, out vec4 rect, out float z) {
  invalid = false;
  rect = vec4(0.0);
  z = 0.0;
  const bool reversed = (pc.flags & GLINT_OBJECT_REVERSED_Z) != 0u;
  const uint kind = floatBitsToUint(w1.w);
  const vec3 a = w0.xyz;
  // Planes' near and far tests widened by the rounding of near_w, far_w.
  const float near_lo = pc.near_w * (1.0 - kEps), near_hi = pc.near_w * (1.0 + kEps);
  const float far_hi = pc.far_w * (1.0 + kEps);  // +Inf for an infinite far plane (FLT_MAX)
  const vec2 len_x = vec2(pc.plane_len[0], pc.plane_len[1]), len_y = vec2(pc.plane_len[2], pc.plane_len[3]);
  float w_near;  // smallest w of the bound, less its error (> near_hi when the Hi-Z test runs)
  if (kind == GLINT_OBJECT_SPHERE) {
    const float radius = w0.w;
    if (!finite3(a) || !finite_f(radius) || !(radius >= 0.0)) {
      invalid = true;
      return GLINT_OBJECT_STATE_VISIBLE;
    }
    float err;
    const vec3 c = to_view(a, err);
    const float r = radius * pc.radius_scale * (1.0 + kEps) + err;
    if (!finite3(c) || !finite_f(r)) return GLINT_OBJECT_STATE_VISIBLE;  // overflow: conservative
    if (c.z - r > far_hi || c.z + r < near_lo) return GLINT_OBJECT_STATE_FRUSTUM;
    const vec2 mx = plane_margin(c.x, c.z, r, pc.proj_x, pc.proj_ox, len_x);
    const vec2 my = plane_margin(c.y, c.z, r, pc.proj_y, pc.proj_oy, len_y);
    if (min(min(mx.x, mx.y), min(my.x, my.y)) < 0.0) return GLINT_OBJECT_STATE_FRUSTUM;
    if (frustum_only || c.z - r < near_hi) return GLINT_OBJECT_STATE_VISIBLE;  // in, or crossing near
#ifndef GLINT_OBJECT_PHASE1
    rect.xy = slopes_to_ndc(sphere_slopes(c.x, c.z, r), pc.proj_x, pc.proj_ox);
    rect.zw = slopes_to_ndc(sphere_slopes(c.y, c.z, r), pc.proj_y, pc.proj_oy);
#endif
    w_near = c.z - r;
  } else if (kind == GLINT_OBJECT_BOX) {
    const vec3 b = w1.xyz;
    if (!finite3(a) || !finite3(b) || !all(lessThanEqual(a, b))) {
      invalid = true;
      return GLINT_OBJECT_STATE_VISIBLE;
    }
    // The corners' error bound: the largest terms of any corner (to_view of the largest absolute
    // coordinates). Below 1e32, every sum of those terms is far from overflow (r is 2^-18 of it), so
    // no corner coordinate below is checked for Inf; a NaN r fails the comparison.
    float r;
    to_view(max(abs(a), abs(b)), r);
    if (!(r < 1e32)) return GLINT_OBJECT_STATE_VISIBLE;  // overflow possible: conservative
    // The box as its centre and three half axes in view space (x, y, w): corner j is
    // c + (+-e0) + (+-e1) + (+-e2). The centre's and half extents' roundings and the sums' are a
    // few units in the last place of the terms r bounds (64 of them): each computed corner is within
    // r of the exact one, as the eight transformed corners were.
    // Halved before the sum: (a + b) or (b - a) exceeds FLT_MAX for coordinates above 2^127 (the
    // corners can still be far below it, as under a view that scales by 0.01), and the NaN the
    // infinite half axis makes (Inf x 0) would reach the Hi-Z test. Halving is exact (normal
    // values), and the halves' sum or difference is at most FLT_MAX. `precise`: not reassociated
    // back into the overflowing form (SPIR-V NoContraction).
    precise const vec3 mid = a * 0.5 + b * 0.5;
    precise const vec3 half_ext = b * 0.5 - a * 0.5;
    float unused;
    const vec3 c = to_view(mid, unused);
    const vec3 e0 = vec3(pc.view_x[0], pc.view_y[0], pc.view_w[0]) * half_ext.x;
    const vec3 e1 = vec3(pc.view_x[1], pc.view_y[1], pc.view_w[1]) * half_ext.y;
    const vec3 e2 = vec3(pc.view_x[2], pc.view_y[2], pc.view_w[2]) * half_ext.z;
    // w over the corners: the centre's w plus or minus the sum of the half axes' |w| (the extremes
    // of a linear function over a box), each side moved by r.
    const float w_spread = abs(e0.z) + abs(e1.z) + abs(e2.z);
    const float w_min = c.z - w_spread, w_max = c.z + w_spread;
    if (w_min - r > far_hi || w_max + r < near_lo) return GLINT_OBJECT_STATE_FRUSTUM;
    // The side planes: all corners outside one plane when its largest margin is negative.
    const vec2 mx = box_margin(c.xz, e0.xz, e1.xz, e2.xz, r, pc.proj_x, pc.proj_ox, len_x);
    const vec2 my = box_margin(c.yz, e0.yz, e1.yz, e2.yz, r, pc.proj_y, pc.proj_oy, len_y);
    if (min(min(mx.x, mx.y), min(my.x, my.y)) < 0.0) return GLINT_OBJECT_STATE_FRUSTUM;
    if (frustum_only || w_min - r < near_hi) return GLINT_OBJECT_STATE_VISIBLE;
#ifndef GLINT_OBJECT_PHASE1
    // The corners' slopes x / w and y / w (in front of the near plane, where every w > r > 0 up to
    // rounding), only for a box that reaches the Hi-Z test. The widening of each slope by its point
    // error r, |d(c / w)| <= r (1 + |c / w|) / (w - r), and the rounding of the reciprocal and
    // product (within kEps |m|) is applied once to the interval: it grows with |m| and 1 / (w - r),
    // so the interval's largest |m| and the smallest corner w bound every corner's.
    vec2 sx = vec2(3.4028235e38, -3.4028235e38), sy = sx;
    float w_lo = 3.4028235e38;
    [[unroll]] for (int j = 0; j < 8; ++j) {
      const vec3 v = c + ((j & 1) != 0 ? e0 : -e0) + ((j & 2) != 0 ? e1 : -e1) + ((j & 4) != 0 ? e2 : -e2);
      const vec2 m = v.xy * (1.0 / v.z);
      sx = vec2(min(sx.x, m.x), max(sx.y, m.x));
      sy = vec2(min(sy.x, m.y), max(sy.y, m.y));
      w_lo = min(w_lo, v.z);
    }
    if (!(w_lo - r > 0.0)) return GLINT_OBJECT_STATE_VISIBLE;  // rounding at the near plane: conservative
    const float k = r * (1.0 / (w_lo - r));
    const float ax = max(abs(sx.x), abs(sx.y)), ay = max(abs(sy.x), abs(sy.y));
    const float ex = k * (1.0 + ax) + kEps * ax, ey = k * (1.0 + ay) + kEps * ay;
    rect.xy = slopes_to_ndc(sx + vec2(-ex, ex), pc.proj_x, pc.proj_ox);
    rect.zw = slopes_to_ndc(sy + vec2(-ey, ey), pc.proj_y, pc.proj_oy);
#endif
    w_near = w_min - r;
  } else {
    invalid = true;
    return GLINT_OBJECT_STATE_VISIBLE;
  }
  z = nearest_depth(w_near, reversed);
  return GLINT_OBJECT_STATE_NONE;
}

void main() {
  const uint lid = gl_LocalInvocationIndex;  // < kThreads: the object's place in the workgroup
  if (lid < 2u * kGroups) s_mask[lid] = 0u;
  if (lid < kGroups) s_counts[lid] = 0u;
  if (lid < 2u) s_ends[lid] = 0u;
  barrier();
  const uint wg = gl_WorkGroupID.y * pc.groups_x + gl_WorkGroupID.x;
  const uint group_count = (pc.count + GLINT_OBJECT_GROUP - 1u) / GLINT_OBJECT_GROUP;
  const uint i = wg * kThreads + lid;
  const uint mode = pc.flags & GLINT_OBJECT_MODE_MASK;
  // 1. Load the kind (coalesced: invocation t, object t) and place the object by kind: spheres (and
  //    the objects not tested) from the first slot up, boxes from the last slot down.
  uint history = GLINT_OBJECT_STATE_NONE;
  bool tested = false;
  if (i < pc.count) {
    history = mode == GLINT_OBJECT_MODE_SINGLE ? GLINT_OBJECT_STATE_NONE : visibility[i];
    tested = mode != GLINT_OBJECT_MODE_PHASE1 || history == GLINT_OBJECT_STATE_VISIBLE;
  }
  vec4 w1 = vec4(0.0);
  if (tested) w1 = object_words[2u * i + 1u];
  const bool box = tested && floatBitsToUint(w1.w) == GLINT_OBJECT_BOX;
  // The slot of the object once sorted: a rank among the workgroup's objects of its kind.
#ifdef GLINT_OBJECT_SUBGROUP
  // One shared atomic per subgroup and kind (per invocation, the invocations of a subgroup
  // contended for the same two words); ranks within the subgroup from the ballot.
  const uvec4 boxes = subgroupBallot(box), others = subgroupBallot(!box);
  uint base_s = 0u, base_b = 0u;
  if (subgroupElect()) {
    base_s = atomicAdd(s_ends[0], subgroupBallotBitCount(others));
    base_b = atomicAdd(s_ends[1], subgroupBallotBitCount(boxes));
  }
  base_s = subgroupBroadcastFirst(base_s);
  base_b = subgroupBroadcastFirst(base_b);
  const uint rank = box ? base_b + subgroupBallotExclusiveBitCount(boxes) : base_s + subgroupBallotExclusiveBitCount(others);
#else
  const uint rank = atomicAdd(s_ends[box ? 1 : 0], 1u);
#endif
  const uint slot = box ? kThreads - 1u - rank : rank;
  barrier();
  // A workgroup of one kind (a scene of spheres only, say) tests its objects where they are; a
  // mixed one sorts their indices through shared memory first (uniform in the workgroup: the
  // barriers below are reached by all or none). Then every invocation loads the record of its
  // slot's object: the lines the kind's load above brought in, read again from cache.
  const bool mixed = s_ends[0] != 0u && s_ends[1] != 0u;
  uint who = lid | (tested ? 0u : kNotTested);
  if (mixed) {
    s_who[slot] = who;
    barrier();
    who = s_who[lid];
  }
  vec4 a0 = vec4(0.0), a1 = vec4(0.0);
  if ((who & kNotTested) == 0u) {
    const uint j = wg * kThreads + who;
    a0 = object_words[2u * j];
    a1 = object_words[2u * j + 1u];
  }
  // 2. Test the object of slot `lid`: in a mixed workgroup, one subgroup at most holds both kinds.
  uint st = GLINT_OBJECT_STATE_NONE;
  bool inv = false;
  if ((who & kNotTested) == 0u) {
    vec4 rect;
    float z;
    st = test_object(a0, a1, mode == GLINT_OBJECT_MODE_PHASE1, inv, rect, z);
#ifndef GLINT_OBJECT_PHASE1
    // One Hi-Z test for both kinds of bound.
    if (st == GLINT_OBJECT_STATE_NONE) st = hiz_test(rect.xy, rect.zw, z, (pc.flags & GLINT_OBJECT_REVERSED_Z) != 0u);
#endif
  }
  uint r = st | (inv ? 4u : 0u);
  if (mixed) {
    s_state[who & ~kNotTested] = r;
    barrier();
    r = s_state[lid];
  }
  // 3. In object order again: the state, the emission bit and the counts of object i.
  const uint state = r & 3u;
  const bool invalid = (r & 4u) != 0u;
  bool emit = false;
  if (tested) {
#ifndef GLINT_OBJECT_PHASE1
    visibility[i] = state;
#endif
    emit = state == GLINT_OBJECT_STATE_VISIBLE &&
           (mode != GLINT_OBJECT_MODE_PHASE2 || history != GLINT_OBJECT_STATE_VISIBLE);
  }
  // Counter 1 + f is byte f of the packed word (compact_pack_counts): frustum, occluded, visible,
  // invalid; each at most 64 per group of 64 objects, so no byte carries into the next.
  uint packed = invalid ? (1u << 24u) : 0u;
  if (state != GLINT_OBJECT_STATE_NONE) {
    packed += 1u << (8u * (state == GLINT_OBJECT_STATE_FRUSTUM ? 0u : state == GLINT_OBJECT_STATE_OCCLUDED ? 1u : 2u));
  }
  const uint word = lid >> 5u;  // the object's mask word: group word >> 1, half word & 1
#ifdef GLINT_OBJECT_SUBGROUP
  // Reduced over the subgroup first (uniform control flow: every invocation gets here), then one
  // invocation per subgroup adds the subgroup's part: a few shared atomics per workgroup instead of
  // two per invocation on the same words, which serialise. The loops run over the words and groups
  // the subgroup's invocations touch (one of each for subgroups of 32 consecutive invocations).
  // Integer OR and sums: the same bits whatever the subgroup size or the mapping of invocations
  // to subgroups.
  const uint bit = emit ? 1u << (lid & 31u) : 0u;
  const uint w_lo = subgroupMin(word), w_hi = subgroupMax(word);
  for (uint w = w_lo; w <= w_hi; ++w) {
    const uint m = subgroupOr(word == w ? bit : 0u);
    if (subgroupElect() && m != 0u) atomicOr(s_mask[w], m);
  }
  for (uint k = w_lo >> 1u; k <= (w_hi >> 1u); ++k) {
    const uint c = subgroupAdd((word >> 1u) == k ? packed : 0u);
    if (subgroupElect() && c != 0u) atomicAdd(s_counts[k], c);
  }
#else
  if (emit) atomicOr(s_mask[word], 1u << (lid & 31u));
  if (packed != 0u) atomicAdd(s_counts[word >> 1u], packed);
#endif
  barrier();
  const uint g = wg * kGroups + lid;  // the group record invocation lid < kGroups writes
  if (lid < kGroups && g < group_count) groups[g] = uvec4(s_mask[2u * lid], s_mask[2u * lid + 1u], s_counts[lid], 0u);
}
