// Float64 reference of the object cull (object_cull_reference.h).
#include "reference/object_cull_reference.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "visibility/shaders/object_cull_params.h"  // the kernel's rounding margin and window limit, shared with the reference

namespace glint::reference {

namespace {

constexpr double kEps = GLINT_OBJECT_EPS;
constexpr double kInf = std::numeric_limits<double>::infinity();

bool finite3(const double v[3]) { return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]); }

// The camera reduced to view-space rows (x, y, w = P32 z) and projection terms, in double.
struct Cam {
  double vx[4], vy[4], vw[4];
  double sx, ox, sy, oy, a, b, near_w, far_w, radius_scale;
};

Cam reduce(const ObjectCamera& c) {
  Cam r{};
  const double s = c.proj[11];
  for (int k = 0; k < 4; ++k) {
    r.vx[k] = c.view[k * 4 + 0];
    r.vy[k] = c.view[k * 4 + 1];
    r.vw[k] = s * c.view[k * 4 + 2];
  }
  r.sx = c.proj[0];
  r.ox = c.proj[8] * s;
  r.sy = c.proj[5];
  r.oy = c.proj[9] * s;
  r.a = c.proj[10] * s;
  r.b = c.proj[14];
  r.near_w = c.reversed_z ? r.b / (1 - r.a) : -r.b / r.a;
  const double far_w = c.reversed_z ? -r.b / r.a : r.b / (1 - r.a);
  r.far_w = far_w > 0 && std::isfinite(far_w) ? far_w : kInf;
  // The bound on the largest singular value of the view's 3x3 that the library documents (the
  // smaller of the Gershgorin bound on V^T V and the Frobenius norm), exact for rotations.
  double frob = 0, g = 0;
  for (int i = 0; i < 3; ++i) {
    double row = 0;
    for (int j = 0; j < 3; ++j) {
      double d = 0;
      for (int k = 0; k < 3; ++k) d += double(c.view[i * 4 + k]) * c.view[j * 4 + k];
      row += std::abs(d);
      frob += double(c.view[i * 4 + j]) * c.view[i * 4 + j];
    }
    g = std::max(g, row);
  }
  r.radius_scale = std::min(std::sqrt(frob), std::sqrt(g));
  return r;
}

double dot4(const double r[4], const double p[3]) { return r[0] * p[0] + r[1] * p[1] + r[2] * p[2] + r[3]; }
double absdot4(const double r[4], const double p[3]) {
  return std::abs(r[0] * p[0]) + std::abs(r[1] * p[1]) + std::abs(r[2] * p[2]) + std::abs(r[3]);
}

// Margins of the two side planes of one axis (see plane_margin in object_cull.comp).
void plane_margin(double c, double w, double r, double s, double o, double f, double out[2]) {
  const double nx[2] = {s, -s}, nw[2] = {1 + o, 1 - o};
  for (int i = 0; i < 2; ++i) {
    const double len = std::sqrt(nx[i] * nx[i] + nw[i] * nw[i]);
    out[i] = nx[i] * c + nw[i] * w + len * r * (1 + f * kEps) + f * kEps * (std::abs(nx[i] * c) + std::abs(nw[i] * w));
  }
}

void sphere_slopes(double c, double w, double r, double f, double out[2]) {
  const double t = std::sqrt(std::max(c * c + (w - r) * (w + r), 0.0));
  const double den = t * w - r * std::abs(c);
  const double err = f * kEps * (t * std::abs(c) + r * w) * (t * w + r * std::abs(c)) / (den * den);
  out[0] = (t * c - r * w) / (t * w + r * c) - err;
  out[1] = (t * c + r * w) / (t * w - r * c) + err;
}

void slopes_to_ndc(const double m[2], double s, double o, double f, double out[2]) {
  const double n0 = s * m[0] + o, n1 = s * m[1] + o;
  const double e = f * kEps * (std::abs(s) * std::max(std::abs(m[0]), std::abs(m[1])) + std::abs(o) + 1);
  out[0] = std::min(n0, n1) - e;
  out[1] = std::max(n0, n1) + e;
}

double nearest_depth(const Cam& cam, double w_min, bool reversed, double f) {
  const double q = cam.b / w_min;
  const double e = f * kEps * (std::abs(cam.a) + std::abs(q));
  return reversed ? cam.a + q + e : cam.a + q - e;
}

bool depth_ok(double d, double z, bool reversed) { return reversed ? d <= z : d >= z; }

uint32_t hiz_test(const double x[2], const double y[2], double z, bool reversed, const DepthImage& depth,
                  const std::vector<DepthImage>& pyramid, double f, bool full_res) {
  const double W = depth.width, H = depth.height;
  const double lo[2] = {(x[0] * 0.5 + 0.5) * W - f * kEps * W * (std::abs(x[0]) + 1),
                        (y[0] * 0.5 + 0.5) * H - f * kEps * H * (std::abs(y[0]) + 1)};
  const double hi[2] = {(x[1] * 0.5 + 0.5) * W + f * kEps * W * (std::abs(x[1]) + 1),
                        (y[1] * 0.5 + 0.5) * H + f * kEps * H * (std::abs(y[1]) + 1)};
  const int size[2] = {int(depth.width), int(depth.height)};
  int p0[2], p1[2];
  for (int a = 0; a < 2; ++a) {
    const double clo = std::clamp(lo[a], 0.0, double(size[a])), chi = std::clamp(hi[a], 0.0, double(size[a]));
    p0[a] = std::min(int(std::floor(clo)), size[a] - 1);
    p1[a] = std::clamp(int(std::ceil(chi)) - 1, p0[a], size[a] - 1);
  }
  if (full_res) {
    for (int py = p0[1]; py <= p1[1]; ++py)
      for (int px = p0[0]; px <= p1[0]; ++px)
        if (depth_ok(depth.at(px, py), z, reversed)) return GLINT_OBJECT_STATE_VISIBLE;
    return GLINT_OBJECT_STATE_OCCLUDED;
  }
  const int span = std::max(p1[0] - p0[0], p1[1] - p0[1]) + 1;
  int k = 0;
  while (span - 1 > (1 << k)) ++k;  // smallest k with span - 1 <= 2^k
  k = std::min(k, int(pyramid.size()));
  const int lw = std::max(1, size[0] >> k), lh = std::max(1, size[1] >> k);
  const int t0x = std::min(p0[0] >> k, lw - 1), t1x = std::min(p1[0] >> k, lw - 1);
  const int t0y = std::min(p0[1] >> k, lh - 1), t1y = std::min(p1[1] >> k, lh - 1);
  if ((t1x - t0x + 1) * (t1y - t0y + 1) > GLINT_OBJECT_MAX_WINDOW) return GLINT_OBJECT_STATE_VISIBLE;
  const DepthImage& level = k == 0 ? depth : pyramid[size_t(k) - 1];
  for (int ty = t0y; ty <= t1y; ++ty)
    for (int tx = t0x; tx <= t1x; ++tx)
      if (depth_ok(level.at(tx, ty), z, reversed)) return GLINT_OBJECT_STATE_VISIBLE;
  return GLINT_OBJECT_STATE_OCCLUDED;
}

}  // namespace

uint32_t object_state(const GlintCullObject& o, const ObjectCamera& camera, const DepthImage& depth,
                      const std::vector<DepthImage>& pyramid, double f, bool full_res, bool frustum_only,
                      bool* invalid) {
  if (invalid) *invalid = false;
  const Cam cam = reduce(camera);
  const bool reversed = camera.reversed_z;
  const double near_lo = cam.near_w * (1 - f * kEps), near_hi = cam.near_w * (1 + f * kEps);
  const double far_hi = cam.far_w * (1 + f * kEps);
  const double a[3] = {o.sphere_or_min[0], o.sphere_or_min[1], o.sphere_or_min[2]};
  if (o.kind == GLINT_OBJECT_SPHERE) {
    const double radius = o.sphere_or_min[3];
    if (!finite3(a) || !std::isfinite(radius) || !(radius >= 0)) {
      if (invalid) *invalid = true;
      return GLINT_OBJECT_STATE_VISIBLE;
    }
    const double c[3] = {dot4(cam.vx, a), dot4(cam.vy, a), dot4(cam.vw, a)};
    const double err = f * kEps * (absdot4(cam.vx, a) + absdot4(cam.vy, a) + absdot4(cam.vw, a));
    const double r = radius * cam.radius_scale * (1 + f * kEps) + err;
    if (c[2] - r > far_hi || c[2] + r < near_lo) return GLINT_OBJECT_STATE_FRUSTUM;
    double mx[2], my[2];
    plane_margin(c[0], c[2], r, cam.sx, cam.ox, f, mx);
    plane_margin(c[1], c[2], r, cam.sy, cam.oy, f, my);
    if (std::min({mx[0], mx[1], my[0], my[1]}) < 0) return GLINT_OBJECT_STATE_FRUSTUM;
    if (frustum_only || c[2] - r < near_hi) return GLINT_OBJECT_STATE_VISIBLE;
    double sx[2], sy[2], x[2], y[2];
    sphere_slopes(c[0], c[2], r, f, sx);
    sphere_slopes(c[1], c[2], r, f, sy);
    slopes_to_ndc(sx, cam.sx, cam.ox, f, x);
    slopes_to_ndc(sy, cam.sy, cam.oy, f, y);
    return hiz_test(x, y, nearest_depth(cam, c[2] - r, reversed, f), reversed, depth, pyramid, f, full_res);
  }
  if (o.kind == GLINT_OBJECT_BOX) {
    const double b[3] = {o.box_max[0], o.box_max[1], o.box_max[2]};
    if (!finite3(a) || !finite3(b) || !(a[0] <= b[0] && a[1] <= b[1] && a[2] <= b[2])) {
      if (invalid) *invalid = true;
      return GLINT_OBJECT_STATE_VISIBLE;
    }
    const double m[3] = {std::max(std::abs(a[0]), std::abs(b[0])), std::max(std::abs(a[1]), std::abs(b[1])),
                         std::max(std::abs(a[2]), std::abs(b[2]))};
    const double r = f * kEps * (absdot4(cam.vx, m) + absdot4(cam.vy, m) + absdot4(cam.vw, m));
    double v[8][3];
    double w_min = kInf, w_max = -kInf;
    double side[4] = {-kInf, -kInf, -kInf, -kInf};
    for (int j = 0; j < 8; ++j) {
      const double p[3] = {(j & 1) ? b[0] : a[0], (j & 2) ? b[1] : a[1], (j & 4) ? b[2] : a[2]};
      v[j][0] = dot4(cam.vx, p);
      v[j][1] = dot4(cam.vy, p);
      v[j][2] = dot4(cam.vw, p);
      w_min = std::min(w_min, v[j][2]);
      w_max = std::max(w_max, v[j][2]);
      double mx[2], my[2];
      plane_margin(v[j][0], v[j][2], r, cam.sx, cam.ox, f, mx);
      plane_margin(v[j][1], v[j][2], r, cam.sy, cam.oy, f, my);
      side[0] = std::max(side[0], mx[0]);
      side[1] = std::max(side[1], mx[1]);
      side[2] = std::max(side[2], my[0]);
      side[3] = std::max(side[3], my[1]);
    }
    if (w_min - r > far_hi || w_max + r < near_lo) return GLINT_OBJECT_STATE_FRUSTUM;
    if (std::min({side[0], side[1], side[2], side[3]}) < 0) return GLINT_OBJECT_STATE_FRUSTUM;
    if (frustum_only || w_min - r < near_hi) return GLINT_OBJECT_STATE_VISIBLE;
    double sx[2] = {kInf, -kInf}, sy[2] = {kInf, -kInf};
    for (int j = 0; j < 8; ++j) {
      const double mx = v[j][0] / v[j][2], my = v[j][1] / v[j][2];
      const double ex = r * (1 + std::abs(mx)) / (v[j][2] - r) + f * kEps * std::abs(mx);
      const double ey = r * (1 + std::abs(my)) / (v[j][2] - r) + f * kEps * std::abs(my);
      sx[0] = std::min(sx[0], mx - ex);
      sx[1] = std::max(sx[1], mx + ex);
      sy[0] = std::min(sy[0], my - ey);
      sy[1] = std::max(sy[1], my + ey);
    }
    double x[2], y[2];
    slopes_to_ndc(sx, cam.sx, cam.ox, f, x);
    slopes_to_ndc(sy, cam.sy, cam.oy, f, y);
    return hiz_test(x, y, nearest_depth(cam, w_min - r, reversed, f), reversed, depth, pyramid, f, full_res);
  }
  if (invalid) *invalid = true;
  return GLINT_OBJECT_STATE_VISIBLE;
}

ObjectVerdict judge_object(const GlintCullObject& object, const ObjectCamera& camera, const DepthImage& depth,
                           const std::vector<DepthImage>& pyramid) {
  ObjectVerdict v;
  v.expected = object_state(object, camera, depth, pyramid, 1.0, false, false, &v.invalid);
  const uint32_t lo = object_state(object, camera, depth, pyramid, 0.5, false, false);
  const uint32_t hi = object_state(object, camera, depth, pyramid, 2.0, false, false);
  v.ambiguous = lo != hi;
  v.brute = object_state(object, camera, depth, pyramid, 0.0, true, false);
  return v;
}

void perspective(double fov_y, double aspect, double n, double f, bool reversed_z, bool flip_y, float out[16]) {
  std::fill(out, out + 16, 0.0f);
  const double t = 1.0 / std::tan(fov_y / 2);
  out[0] = static_cast<float>(t / aspect);
  out[5] = static_cast<float>(flip_y ? -t : t);
  out[11] = -1.0f;  // w = -z_view (right-handed view, looking down -z)
  // depth = (P22 z + P23) / -z: standard 0 at z = -n, 1 at z = -f; reversed the other way round.
  if (f <= 0) {
    out[10] = reversed_z ? 0.0f : -1.0f;
    out[14] = static_cast<float>(reversed_z ? n : -n);
  } else if (reversed_z) {
    out[10] = static_cast<float>(n / (f - n));
    out[14] = static_cast<float>(n * f / (f - n));
  } else {
    out[10] = static_cast<float>(-f / (f - n));
    out[14] = static_cast<float>(-n * f / (f - n));
  }
}

}  // namespace glint::reference
