#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_samplerless_texture_functions : require
// PREVIOUS FORM, kept for benchmarks (detail::object_cull_use_previous_kernel): object_cull.comp
// is the kernel glint runs. Frustum and Hi-Z occlusion test of caller objects (world-space spheres or boxes), the first of
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
// GLINT_OBJECT_PHASE1 builds the phase-1 variant, which binds no image (the depth image may be a
// render target while phase 1 runs).
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

layout(std430, binding = BINDING_OBJECTS) readonly buffer Objects { GlintCullObject objects[]; };
#ifdef GLINT_OBJECT_PHASE1
layout(std430, binding = BINDING_VISIBILITY) readonly buffer Visibility { uint visibility[]; };
#else
layout(std430, binding = BINDING_VISIBILITY) buffer Visibility { uint visibility[]; };
#endif
#define COMPACT_GROUPS_BINDING BINDING_GROUPS  // the compaction's group buffer: this writes the masks (x, y)
#define COMPACT_NO_SCAN
#include "compact.glsl"
layout(push_constant) uniform Push { GlintObjectCullPush pc; };

shared uint s_mask[2];
shared uint s_frustum, s_occluded, s_visible, s_invalid;

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

// The slopes c / w of the two lines through the eye tangent to the disc of centre (c, w) and
// radius r in one axis plane (w > r), widened by their fp32 error (Mara & McGuire 2013, section 3;
// the form of zeux/niagara that divides without cancellation in the numerator's sign).
vec2 sphere_slopes(float c, float w, float r) {
  // Beyond 2^60 the bound is scaled by 2^-100 (exact; the slopes are ratios), so that the squares
  // below stay in the fp32 range, as in object_cull.comp.
  if (max(abs(c), w) > 1152921504606846976.0) {  // 2^60
    const float k = 7.888609052210118e-31;         // 2^-100
    c *= k;
    w *= k;
    r *= k;
  }
  const float t = sqrt(max(c * c + (w - r) * (w + r), 0.0));  // length of the tangent
  const float lo = (t * c - r * w) / (t * w + r * c);
  const float hi = (t * c + r * w) / (t * w - r * c);
  const float den = t * w - r * abs(c);                        // the smaller denominator, > 0
  // Each factor divided by den on its own: their product (about w^4) and den^2 leave the fp32
  // range from w = 2^32 on (a NaN or zero bound).
  const float err = kEps * ((t * abs(c) + r * w) / den) * ((t * w + r * abs(c)) / den);
  return vec2(lo - err, hi + err);
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
    vec4 d;
    if (k == 0) {
      d = vec4(texelFetch(depth_tex, t0, 0).r, texelFetch(depth_tex, ivec2(t1.x, t0.y), 0).r,
               texelFetch(depth_tex, ivec2(t0.x, t1.y), 0).r, texelFetch(depth_tex, t1, 0).r);
    } else {
      d = vec4(texelFetch(hiz_tex, t0, k - 1).r, texelFetch(hiz_tex, ivec2(t1.x, t0.y), k - 1).r,
               texelFetch(hiz_tex, ivec2(t0.x, t1.y), k - 1).r, texelFetch(hiz_tex, t1, k - 1).r);
    }
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

// The state of one object; `invalid` is set for malformed bounds (counted visible).
uint test_object(GlintCullObject o, bool frustum_only, out bool invalid) {
  invalid = false;
  const bool reversed = (pc.flags & GLINT_OBJECT_REVERSED_Z) != 0u;
  const vec3 a = vec3(o.sphere_or_min[0], o.sphere_or_min[1], o.sphere_or_min[2]);
  // Planes' near and far tests widened by the rounding of near_w, far_w.
  const float near_lo = pc.near_w * (1.0 - kEps), near_hi = pc.near_w * (1.0 + kEps);
  const float far_hi = pc.far_w * (1.0 + kEps);  // +Inf for an infinite far plane (FLT_MAX)
  if (o.kind == GLINT_OBJECT_SPHERE) {
    const float radius = o.sphere_or_min[3];
    if (!finite3(a) || !finite_f(radius) || !(radius >= 0.0)) {
      invalid = true;
      return GLINT_OBJECT_STATE_VISIBLE;
    }
    float err;
    const vec3 c = to_view(a, err);
    const float r = radius * pc.radius_scale * (1.0 + kEps) + err;
    if (!finite3(c) || !finite_f(r)) return GLINT_OBJECT_STATE_VISIBLE;  // overflow: conservative
    if (c.z - r > far_hi || c.z + r < near_lo) return GLINT_OBJECT_STATE_FRUSTUM;
    const vec2 mx = plane_margin(c.x, c.z, r, pc.proj_x, pc.proj_ox, vec2(pc.plane_len[0], pc.plane_len[1]));
    const vec2 my = plane_margin(c.y, c.z, r, pc.proj_y, pc.proj_oy, vec2(pc.plane_len[2], pc.plane_len[3]));
    if (min(min(mx.x, mx.y), min(my.x, my.y)) < 0.0) return GLINT_OBJECT_STATE_FRUSTUM;
    if (frustum_only || c.z - r < near_hi) return GLINT_OBJECT_STATE_VISIBLE;  // in, or crossing near
#ifndef GLINT_OBJECT_PHASE1
    const vec2 x = slopes_to_ndc(sphere_slopes(c.x, c.z, r), pc.proj_x, pc.proj_ox);
    const vec2 y = slopes_to_ndc(sphere_slopes(c.y, c.z, r), pc.proj_y, pc.proj_oy);
    return hiz_test(x, y, nearest_depth(c.z - r, reversed), reversed);
#endif
  } else if (o.kind == GLINT_OBJECT_BOX) {
    const vec3 b = vec3(o.box_max[0], o.box_max[1], o.box_max[2]);
    if (!finite3(a) || !finite3(b) || !all(lessThanEqual(a, b))) {
      invalid = true;
      return GLINT_OBJECT_STATE_VISIBLE;
    }
    // The corners' error bound: the largest terms of any corner.
    float r;
    to_view(max(abs(a), abs(b)), r);
    float w_min = 3.4028235e38, w_max = -3.4028235e38;
    vec4 side = vec4(-3.4028235e38);  // max over corners of the four side-plane margins
    const vec2 len_x = vec2(pc.plane_len[0], pc.plane_len[1]), len_y = vec2(pc.plane_len[2], pc.plane_len[3]);
    // The corners' slope intervals, in the same pass (no array of corners is kept; used only
    // when the box is in front of the near plane, where w - r > 0). Each slope is widened by its
    // point error r (|d(c / w)| <= r (1 + |c / w|) / (w - r)) and the rounding of the reciprocal
    // and products (a few units in the last place of |m|, within kEps |m|).
    vec2 sx = vec2(3.4028235e38, -3.4028235e38), sy = sx;
    for (int j = 0; j < 8; ++j) {
      float unused;
      const vec3 v = to_view(vec3((j & 1) != 0 ? b.x : a.x, (j & 2) != 0 ? b.y : a.y, (j & 4) != 0 ? b.z : a.z), unused);
      if (!finite3(v)) return GLINT_OBJECT_STATE_VISIBLE;
      w_min = min(w_min, v.z);
      w_max = max(w_max, v.z);
      side = max(side, vec4(plane_margin(v.x, v.z, r, pc.proj_x, pc.proj_ox, len_x),
                            plane_margin(v.y, v.z, r, pc.proj_y, pc.proj_oy, len_y)));
#ifndef GLINT_OBJECT_PHASE1
      const vec2 m = v.xy * (1.0 / v.z);
      const vec2 e = (r * (1.0 / (v.z - r))) * (1.0 + abs(m)) + kEps * abs(m);
      sx = vec2(min(sx.x, m.x - e.x), max(sx.y, m.x + e.x));
      sy = vec2(min(sy.x, m.y - e.y), max(sy.y, m.y + e.y));
#endif
    }
    if (!finite_f(r)) return GLINT_OBJECT_STATE_VISIBLE;
    if (w_min - r > far_hi || w_max + r < near_lo) return GLINT_OBJECT_STATE_FRUSTUM;
    if (min(min(side.x, side.y), min(side.z, side.w)) < 0.0) return GLINT_OBJECT_STATE_FRUSTUM;
    if (frustum_only || w_min - r < near_hi) return GLINT_OBJECT_STATE_VISIBLE;
#ifndef GLINT_OBJECT_PHASE1
    const vec2 x = slopes_to_ndc(sx, pc.proj_x, pc.proj_ox);
    const vec2 y = slopes_to_ndc(sy, pc.proj_y, pc.proj_oy);
    return hiz_test(x, y, nearest_depth(w_min - r, reversed), reversed);
#endif
  } else {
    invalid = true;
  }
  return GLINT_OBJECT_STATE_VISIBLE;
}

void main() {
  const uint lid = gl_LocalInvocationIndex;  // < GLINT_OBJECT_GROUP: the bit of this object
  if (lid == 0u) {
    s_mask[0] = 0u;
    s_mask[1] = 0u;
    s_frustum = 0u;
    s_occluded = 0u;
    s_visible = 0u;
    s_invalid = 0u;
  }
  barrier();
  const uint group = gl_WorkGroupID.y * pc.groups_x + gl_WorkGroupID.x;
  const uint group_count = (pc.count + GLINT_OBJECT_GROUP - 1u) / GLINT_OBJECT_GROUP;
  const uint i = group * GLINT_OBJECT_GROUP + lid;
  const uint mode = pc.flags & GLINT_OBJECT_MODE_MASK;
  uint state = GLINT_OBJECT_STATE_NONE;
  bool emit = false, invalid = false;
  if (group < group_count && i < pc.count) {
    const uint history = mode == GLINT_OBJECT_MODE_SINGLE ? GLINT_OBJECT_STATE_NONE : visibility[i];
    if (mode != GLINT_OBJECT_MODE_PHASE1 || history == GLINT_OBJECT_STATE_VISIBLE) {
      state = test_object(objects[i], mode == GLINT_OBJECT_MODE_PHASE1, invalid);
      emit = state == GLINT_OBJECT_STATE_VISIBLE &&
             (mode != GLINT_OBJECT_MODE_PHASE2 || history != GLINT_OBJECT_STATE_VISIBLE);
#ifndef GLINT_OBJECT_PHASE1
      visibility[i] = state;
#endif
    }
  }
  if (emit) atomicOr(s_mask[lid >> 5u], 1u << (lid & 31u));
  if (state == GLINT_OBJECT_STATE_FRUSTUM) atomicAdd(s_frustum, 1u);
  if (state == GLINT_OBJECT_STATE_OCCLUDED) atomicAdd(s_occluded, 1u);
  if (state == GLINT_OBJECT_STATE_VISIBLE) atomicAdd(s_visible, 1u);
  if (invalid) atomicAdd(s_invalid, 1u);
  barrier();
  if (lid == 0u && group < group_count) {  // the counts go to the header through the tile scan
    groups[group] = uvec4(s_mask[0], s_mask[1], compact_pack_counts(uvec4(s_frustum, s_occluded, s_visible, s_invalid)), 0u);
  }
}
