#include "reference/occlusion_reference.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>

#include "visibility/shaders/light_cull_params.h"

namespace glint::reference {

namespace {

uint32_t level_extent(uint32_t size, uint32_t k) { return std::max(1u, size >> k); }

// Source pixels [first, last] covered by texel c of level k of an axis of `size` pixels.
void coverage(uint32_t c, uint32_t k, uint32_t size, uint32_t& first, uint32_t& last) {
  const uint32_t n = level_extent(size, k);
  first = c << k;
  last = c + 1 == n ? size - 1 : ((c + 1) << k) - 1;
}

bool near_integer(double v, double tolerance) { return std::fabs(v - std::round(v)) < tolerance; }

}  // namespace

std::pair<int, int> sample_footprint(uint32_t i, uint32_t j, uint32_t n, bool regular_grid) {
  const int ii = static_cast<int>(i), jj = static_cast<int>(j), nn = static_cast<int>(n);
  if (regular_grid) return {2 * nn * ii, 2 * nn * (ii + 1)};
  // Sample at i + (j + 0.5) / n cells = 2n i + 2j + 1 units; one cell (2n units) wide around it.
  const int centre = 2 * nn * ii + 2 * jj + 1;
  // Outer border: (n - 1) units further out, so that the footprints cover the whole light.
  return {ii == 0 ? 2 * jj + 2 - 2 * nn : centre - nn, ii == nn - 1 ? 2 * nn * nn + 2 * jj : centre + nn};
}

bool depth_visible(double d, double z, const CullSettings& s) {
  return s.reversed_z ? d <= z + s.depth_bias : d >= z - s.depth_bias;
}

std::vector<DepthImage> hiz_pyramid(const DepthImage& depth, bool reversed_z, uint32_t levels) {
  std::vector<DepthImage> out;
  for (uint32_t k = 1; k <= levels; ++k) {
    DepthImage l;
    l.width = level_extent(depth.width, k);
    l.height = level_extent(depth.height, k);
    l.depth.resize(size_t(l.width) * l.height);
    for (uint32_t ty = 0; ty < l.height; ++ty) {
      uint32_t y0, y1;
      coverage(ty, k, depth.height, y0, y1);
      for (uint32_t tx = 0; tx < l.width; ++tx) {
        uint32_t x0, x1;
        coverage(tx, k, depth.width, x0, x1);
        float v = depth.at(x0, y0);
        for (uint32_t y = y0; y <= y1; ++y) {
          for (uint32_t x = x0; x <= x1; ++x)
            v = reversed_z ? std::min(v, depth.at(x, y)) : std::max(v, depth.at(x, y));
        }
        l.depth[size_t(ty) * l.width + tx] = v;
      }
    }
    out.push_back(std::move(l));
  }
  return out;
}

LightVisibility cull_light(const GlintFlareLight& light, const CullSettings& s, const DepthImage& depth,
                           const std::vector<DepthImage>& pyramid) {
  LightVisibility r;
  if (light.enabled == 0) return r;
  // A non-finite float field disables the light (docs/OCCLUSION.md, "Non-finite input").
  for (float v : {light.position_x, light.position_y, light.position_z, light.intensity, light.color_r, light.color_g,
                  light.color_b, light.size_px}) {
    if (!std::isfinite(v)) return r;
  }
  r.culled = GLINT_FLARE_FRUSTUM;
  const double p[4] = {light.position_x, light.position_y, light.position_z, 1.0};
  double clip[4];
  double scale[4];  // sum of |terms|: the size of fp32 rounding in each component
  for (int row = 0; row < 4; ++row) {
    clip[row] = 0.0;
    scale[row] = 0.0;
    for (int col = 0; col < 4; ++col) {
      clip[row] += s.view_proj[col * 4 + row] * p[col];
      scale[row] += std::fabs(s.view_proj[col * 4 + row] * p[col]);
    }
  }
  constexpr double kRel = 1e-5;  // generous against fp32 rounding (2^-24 = 6e-8 per operation)
  if (std::fabs(clip[3]) <= kRel * scale[3]) r.ambiguous = true;
  if (!(clip[3] > 0.0)) return r;
  const double ndc[3] = {clip[0] / clip[3], clip[1] / clip[3], clip[2] / clip[3]};
  for (int i = 0; i < 3; ++i) {
    const double err = kRel * (scale[i] + std::fabs(ndc[i]) * scale[3]) / clip[3];
    const double edges[2] = {i < 2 ? s.margin_ndc : 0.0, i < 2 ? -s.margin_ndc : 1.0};
    for (double e : edges) {
      if (std::fabs(ndc[i] - e) <= err) r.ambiguous = true;
    }
  }
  if (!(std::fabs(ndc[0]) <= s.margin_ndc && std::fabs(ndc[1]) <= s.margin_ndc && ndc[2] >= 0.0 && ndc[2] <= 1.0))
    return r;

  const double w = depth.width, h = depth.height;
  r.center_x = (ndc[0] * 0.5 + 0.5) * w;
  r.center_y = (ndc[1] * 0.5 + 0.5) * h;
  r.ndc_z = ndc[2];
  const double size = light.size_px >= 1.0f ? std::min<double>(light.size_px, GLINT_CULL_MAX_SIZE_PX) : 1.0;
  const uint32_t n = s.grid;
  const double cell = size / n;
  int k = 0;
  if (cell > 1.0) {
    k = static_cast<int>(std::ceil(std::log2(cell)));
    if (near_integer(std::log2(cell), 1e-6)) r.ambiguous = true;
  }
  k = std::min<int>(k, static_cast<int>(s.levels));
  r.level = static_cast<uint32_t>(k);
  const uint32_t lw = level_extent(depth.width, k), lh = level_extent(depth.height, k);
  auto level_at = [&](uint32_t x, uint32_t y) -> double {
    return k == 0 ? depth.at(x, y) : pyramid[k - 1].depth[size_t(y) * lw + x];
  };
  // Position error of a footprint edge, in pixels: the centre's fp32 error plus the cell arithmetic.
  // fp32 error of an edge: ~3 ulp of the centre (projection) plus ~2 ulp of the edge arithmetic.
  const double tol_x = 1e-4 + 5e-7 * (std::fabs(r.center_x) + size);
  const double tol_y = 1e-4 + 5e-7 * (std::fabs(r.center_y) + size);
  const double z = ndc[2];
  const double z_tol = 1e-5 * (1.0 + std::fabs(z));
  const double ox = r.center_x - 0.5 * size, oy = r.center_y - 0.5 * size;

  // Texels of level k under pixels [lo, hi) of an axis, clamp to edge. A footprint edge within
  // fp32 rounding of a multiple of the texel size could land in either texel on the GPU.
  const double texel = std::ldexp(1.0, k);
  auto texels = [&](double lo, double hi, uint32_t pixels, uint32_t lsize, double tol, uint32_t& t0, uint32_t& t1) {
    if (near_integer(lo / texel, tol / texel) || near_integer(hi / texel, tol / texel)) r.ambiguous = true;
    const double last = pixels - 1.0;
    const auto p0 = static_cast<uint32_t>(std::clamp(std::floor(lo), 0.0, last));
    const auto p1 = static_cast<uint32_t>(std::clamp(std::ceil(hi) - 1.0, 0.0, last));
    t0 = std::min(p0 >> k, lsize - 1);
    t1 = std::min(std::max(p0, p1) >> k, lsize - 1);
  };
  // Pixels [p0, p1] overlapping [lo, hi) of an axis, clamp to edge.
  auto pixel_span = [](double lo, double hi, uint32_t pixels, uint32_t& p0, uint32_t& p1) {
    const double last = pixels - 1.0;
    p0 = static_cast<uint32_t>(std::clamp(std::floor(lo), 0.0, last));
    p1 = std::max(p0, static_cast<uint32_t>(std::clamp(std::ceil(hi) - 1.0, 0.0, last)));
  };
  const double unit = size / (2.0 * n * n);  // sample_footprint()'s unit: cell / (2N)
  // Visible pixels per rectangle, from a summed-area table over every pixel a window or cell can
  // reach: the footprint plus half a cell, one pixel and two texels (the wider last texel of a
  // row or column) on each side, clamped to the image.
  const double margin = cell + 2.0 * texel + 2.0;
  // Widened to whole texels: a window clamped at the image edge reads the edge texel.
  uint32_t rx0, rx1, ry0, ry1, unused;
  coverage(std::min(static_cast<uint32_t>(std::clamp(std::floor(ox - margin), 0.0, w - 1.0)) >> k, lw - 1), k,
           depth.width, rx0, unused);
  coverage(std::min(static_cast<uint32_t>(std::clamp(std::ceil(ox + size + margin), 0.0, w - 1.0)) >> k, lw - 1), k,
           depth.width, unused, rx1);
  coverage(std::min(static_cast<uint32_t>(std::clamp(std::floor(oy - margin), 0.0, h - 1.0)) >> k, lh - 1), k,
           depth.height, ry0, unused);
  coverage(std::min(static_cast<uint32_t>(std::clamp(std::ceil(oy + size + margin), 0.0, h - 1.0)) >> k, lh - 1), k,
           depth.height, unused, ry1);
  const size_t rw = rx1 - rx0 + 2;
  std::vector<uint32_t> sat(rw * (ry1 - ry0 + 2), 0u);
  for (uint32_t y = ry0; y <= ry1; ++y) {
    uint32_t row = 0;
    for (uint32_t x = rx0; x <= rx1; ++x) {
      row += depth_visible(depth.at(x, y), z, s) ? 1u : 0u;
      sat[(y - ry0 + 1) * rw + (x - rx0 + 1)] = sat[(y - ry0) * rw + (x - rx0 + 1)] + row;
    }
  }
  auto visible_in = [&](uint32_t x0, uint32_t x1, uint32_t y0, uint32_t y1) -> uint64_t {
    if (x0 < rx0 || x1 > rx1 || y0 < ry0 || y1 > ry1) throw std::logic_error("occlusion reference: window outside");
    const size_t a = (y0 - ry0) * rw + (x0 - rx0), b = (y0 - ry0) * rw + (x1 - rx0 + 1);
    const size_t c = (y1 - ry0 + 1) * rw + (x0 - rx0), d = (y1 - ry0 + 1) * rw + (x1 - rx0 + 1);
    return uint64_t(sat[d]) + sat[a] - sat[b] - sat[c];
  };
  uint32_t visible_cells = 0;
  for (uint32_t j = 0; j < n; ++j) {
    for (uint32_t i = 0; i < n; ++i) {
      const auto fx = sample_footprint(i, j, n, s.regular_grid), fy = sample_footprint(j, i, n, s.regular_grid);
      uint32_t tx0, tx1, ty0, ty1;
      texels(ox + fx.first * unit, ox + fx.second * unit, depth.width, lw, tol_x, tx0, tx1);
      texels(oy + fy.first * unit, oy + fy.second * unit, depth.height, lh, tol_y, ty0, ty1);
      const bool unread = (tx1 - tx0 + 1) * (ty1 - ty0 + 1) > GLINT_CULL_MAX_WINDOW_TEXELS;
      bool seen = unread;
      for (uint32_t y = ty0; y <= ty1 && !unread; ++y) {
        for (uint32_t x = tx0; x <= tx1; ++x) {
          const double d = level_at(x, y);
          if (std::fabs(d - (s.reversed_z ? z + s.depth_bias : z - s.depth_bias)) <= z_tol) r.ambiguous = true;
          seen = seen || depth_visible(d, z, s);
        }
      }
      visible_cells += seen ? 1 : 0;
      // Mixed: the window's pixels and the cell's pixels hold both visible and occluded pixels.
      uint32_t px0, px1, py0, py1;
      coverage(tx0, k, depth.width, px0, unused);
      coverage(tx1, k, depth.width, unused, px1);
      coverage(ty0, k, depth.height, py0, unused);
      coverage(ty1, k, depth.height, unused, py1);
      uint32_t cx0, cx1, cy0, cy1;
      pixel_span(ox + i * cell, ox + (i + 1) * cell, depth.width, cx0, cx1);
      pixel_span(oy + j * cell, oy + (j + 1) * cell, depth.height, cy0, cy1);
      const uint64_t window_visible = visible_in(px0, px1, py0, py1), cell_visible = visible_in(cx0, cx1, cy0, cy1);
      const bool any_visible = window_visible > 0 || cell_visible > 0;
      const bool any_occluded = window_visible < uint64_t(px1 - px0 + 1) * (py1 - py0 + 1) ||
                                cell_visible < uint64_t(cx1 - cx0 + 1) * (cy1 - cy0 + 1);
      if (unread || (any_visible && any_occluded)) ++r.mixed_cells;
    }
  }
  r.grid_fraction = double(visible_cells) / double(n * n);
  r.culled = visible_cells > 0 ? GLINT_FLARE_VISIBLE : GLINT_FLARE_OCCLUDED;

  // Brute force: every pixel under the footprint (clamp to edge), weighted by its overlap area.
  const double x1 = ox + size, y1 = oy + size;
  double visible_area = 0.0;
  for (double py = std::floor(oy); py < y1; py += 1.0) {
    const double hy = std::min(py + 1.0, y1) - std::max(py, oy);
    const auto cy = static_cast<uint32_t>(std::clamp(py, 0.0, h - 1.0));
    for (double px = std::floor(ox); px < x1; px += 1.0) {
      const auto cx = static_cast<uint32_t>(std::clamp(px, 0.0, w - 1.0));
      if (depth_visible(depth.at(cx, cy), z, s)) visible_area += hy * (std::min(px + 1.0, x1) - std::max(px, ox));
    }
  }
  r.brute_force = visible_area / (size * size);
  return r;
}

void camera_view_proj(const Camera& c, double m[16]) {
  // glm::perspectiveRH_ZO; reversed Z maps z to w - z (row 2 = row 3 - row 2).
  const double f = 1.0 / std::tan(c.fov_y / 2.0);
  std::fill(m, m + 16, 0.0);
  m[0] = f / c.aspect;
  m[5] = f;
  m[10] = c.far_z / (c.near_z - c.far_z);
  m[11] = -1.0;
  m[14] = -(c.far_z * c.near_z) / (c.far_z - c.near_z);
  if (c.reversed_z) {
    m[10] = m[11] - m[10];
    m[14] = m[15] - m[14];
  }
}

void camera_unproject(const Camera& c, double x, double y, double z, float out[3]) {
  const double f = 1.0 / std::tan(c.fov_y / 2.0);
  const double a = c.far_z / (c.near_z - c.far_z), b = -(c.far_z * c.near_z) / (c.far_z - c.near_z);
  const double zs = c.reversed_z ? 1.0 - z : z;  // standard NDC depth
  // zs = (a * zv + b) / -zv  =>  zv = -b / (zs + a); w = -zv.
  const double zv = -b / (zs + a);
  const double w = -zv;
  out[0] = static_cast<float>(x * w * c.aspect / f);
  out[1] = static_cast<float>(y * w / f);
  out[2] = static_cast<float>(zv);
}

Scene random_scene(uint32_t width, uint32_t height, uint32_t light_count, uint32_t stream, bool reversed_z,
                   double max_size_px) {
  std::mt19937 rng(stream);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  Scene s;
  s.camera.aspect = double(width) / height;
  s.camera.reversed_z = reversed_z;
  camera_view_proj(s.camera, s.view_proj);
  s.depth.width = width;
  s.depth.height = height;
  std::vector<double> d(size_t(width) * height, 1.0);  // standard depth: far plane
  const int boxes = std::clamp(int(width * height / 2000), 3, 40);
  for (int i = 0; i < boxes; ++i) {
    const double bw = (0.05 + 0.4 * unit(rng)) * width + 1, bh = (0.05 + 0.4 * unit(rng)) * height + 1;
    const double x0 = (-0.1 + 1.2 * unit(rng)) * width - bw / 2, y0 = (-0.1 + 1.2 * unit(rng)) * height - bh / 2;
    const double base = 0.05 + 0.93 * unit(rng);
    const double gx = (unit(rng) - 0.5) * 2e-3, gy = (unit(rng) - 0.5) * 2e-3;
    for (uint32_t y = 0; y < height; ++y) {
      for (uint32_t x = 0; x < width; ++x) {
        if (x + 0.5 < x0 || x + 0.5 > x0 + bw || y + 0.5 < y0 || y + 0.5 > y0 + bh) continue;
        const double v = std::clamp(base + gx * (x - x0) + gy * (y - y0), 0.0, 1.0);
        double& t = d[size_t(y) * width + x];
        t = std::min(t, v);
      }
    }
  }
  s.depth.depth.resize(d.size());
  for (size_t i = 0; i < d.size(); ++i) s.depth.depth[i] = static_cast<float>(reversed_z ? 1.0 - d[i] : d[i]);

  for (uint32_t i = 0; i < light_count; ++i) {
    GlintFlareLight l{};
    const double kind = unit(rng);
    double x = -1.05 + 2.1 * unit(rng), y = -1.05 + 2.1 * unit(rng), z = 0.02 + 0.98 * unit(rng);
    if (kind < 0.1) {  // on a screen edge
      (unit(rng) < 0.5 ? x : y) = (unit(rng) < 0.5 ? -1.0 : 1.0) + (unit(rng) - 0.5) * 0.02;
    } else if (kind < 0.2) {  // off screen, inside or outside the 1.2 margin
      (unit(rng) < 0.5 ? x : y) = (unit(rng) < 0.5 ? -1.0 : 1.0) * (1.0 + 0.35 * unit(rng));
    } else if (kind < 0.25) {  // beyond the far plane
      z = 1.0005 + 0.5 * unit(rng);
    }
    float p[3];
    camera_unproject(s.camera, x, y, reversed_z ? 1.0 - z : z, p);
    if (kind >= 0.25 && kind < 0.33) {  // behind the camera: mirror through the eye
      for (float& c : p) c = -c;
    }
    l.position_x = p[0];
    l.position_y = p[1];
    l.position_z = p[2];
    l.intensity = static_cast<float>(unit(rng) * 2.0);
    l.color_r = static_cast<float>(unit(rng));
    l.color_g = static_cast<float>(unit(rng));
    l.color_b = static_cast<float>(unit(rng));
    l.size_px = static_cast<float>(0.5 + (max_size_px - 0.5) * unit(rng));
    l.element = i % GLINT_FLARE_ELEMENT_COUNT;
    l.enabled = unit(rng) < 0.9 ? 1u : 0u;
    s.lights.push_back(l);
  }
  return s;
}

}  // namespace glint::reference
