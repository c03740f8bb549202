#include "reference/flare_reference.h"

#include <glint/gpu/lod.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "flare/shaders/flare_params.h"
#include "reference/lod_reference.h"

namespace glint::reference {

namespace {

double window(double r) {
  const double t = std::max(1.0 - r * r, 0.0);
  return t * t;
}
double gauss(double x, double sigma) { return std::exp(-(x * x) / (2.0 * sigma * sigma)); }
double smoothstep(double e0, double e1, double x) {
  const double t = std::clamp((x - e0) / (e1 - e0), 0.0, 1.0);
  return t * t * (3.0 - 2.0 * t);
}
double ring(double r, double c) { return std::exp(-((r - c) / 0.06) * ((r - c) / 0.06)); }

}  // namespace

std::array<double, 4> flare_element(uint32_t element, double qx, double qy) {
  const double r = std::sqrt(qx * qx + qy * qy);
  switch (element) {
    case GLINT_FLARE_ELEMENT_GLOW: {
      const double g = std::exp(-8.0 * r * r) * window(r);
      return {g, g, g, g};
    }
    case GLINT_FLARE_ELEMENT_STREAK: {
      const double wide = gauss(qx, 0.35) * gauss(qy, 0.22);
      const double bulge = gauss(qx, 0.08) * gauss(qy, 0.3);
      const double g = (wide + 0.6 * bulge) / 1.6 * window(std::fabs(qx)) * window(std::fabs(qy));
      return {g, g, g, g};
    }
    case GLINT_FLARE_ELEMENT_HALO: {
      const double w = 0.8 * window(r);
      const double rr = w * ring(r, 0.74), gg = w * ring(r, 0.70), bb = w * ring(r, 0.66);
      return {rr, gg, bb, std::max({rr, gg, bb})};
    }
    case GLINT_FLARE_ELEMENT_STARBURST: {
      const double c = r > 0.0 ? qx / r : 1.0;
      const double cos3 = 4.0 * c * c * c - 3.0 * c;  // cos(3 theta)
      const double s = cos3 * cos3;
      const double g = window(r) * (0.8 * std::pow(s, 24) * std::exp(-3.0 * r) +
                                    0.35 * std::pow(1.0 - s, 24) * std::exp(-5.0 * r) + std::exp(-40.0 * r * r));
      return {g, g, g, std::min(g, 1.0)};
    }
    default: {  // ghost: hexagonal aperture, red slightly larger than blue
      const double h = std::max(std::fabs(qy), std::fabs(qx) * 0.8660254 + std::fabs(qy) * 0.5);
      std::array<double, 4> out{};
      const double scale[3] = {0.97, 1.0, 1.03};
      for (int ch = 0; ch < 3; ++ch) {
        const double hh = h * scale[ch];
        const double body = 1.0 - smoothstep(0.62, 0.72, hh);
        const double rim = std::exp(-((hh - 0.68) / 0.05) * ((hh - 0.68) / 0.05));
        out[ch] = (0.35 * body + 0.5 * rim) * window(r);
      }
      out[3] = std::max({out[0], out[1], out[2]});
      return out;
    }
  }
}

std::array<uint32_t, 4> flare_tile(uint32_t element) {
  switch (element) {
    case GLINT_FLARE_ELEMENT_STREAK:
      return {GLINT_FLARE_TILE_STREAK_X, GLINT_FLARE_TILE_STREAK_Y, GLINT_FLARE_TILE_STREAK_W,
              GLINT_FLARE_TILE_STREAK_H};
    case GLINT_FLARE_ELEMENT_HALO:
      return {GLINT_FLARE_TILE_HALO_X, GLINT_FLARE_TILE_HALO_Y, GLINT_FLARE_TILE_HALO_W, GLINT_FLARE_TILE_HALO_H};
    case GLINT_FLARE_ELEMENT_STARBURST:
      return {GLINT_FLARE_TILE_STARBURST_X, GLINT_FLARE_TILE_STARBURST_Y, GLINT_FLARE_TILE_STARBURST_W,
              GLINT_FLARE_TILE_STARBURST_H};
    case GLINT_FLARE_ELEMENT_GHOST:
      return {GLINT_FLARE_TILE_GHOST_X, GLINT_FLARE_TILE_GHOST_Y, GLINT_FLARE_TILE_GHOST_W, GLINT_FLARE_TILE_GHOST_H};
    default:
      return {GLINT_FLARE_TILE_GLOW_X, GLINT_FLARE_TILE_GLOW_Y, GLINT_FLARE_TILE_GLOW_W, GLINT_FLARE_TILE_GLOW_H};
  }
}

FlareAtlasLevel flare_atlas_level0() {
  FlareAtlasLevel l{GLINT_FLARE_ATLAS_WIDTH, GLINT_FLARE_ATLAS_HEIGHT, {}};
  l.rgba.assign(size_t(l.width) * l.height * 4, 0.0);
  for (uint32_t e = 0; e < GLINT_FLARE_ELEMENT_COUNT; ++e) {
    const auto t = flare_tile(e);
    for (uint32_t j = 0; j < t[3]; ++j) {
      for (uint32_t i = 0; i < t[2]; ++i) {
        const auto v = flare_element(e, (i + 0.5) / t[2] * 2.0 - 1.0, (j + 0.5) / t[3] * 2.0 - 1.0);
        std::copy(v.begin(), v.end(), l.at(t[0] + i, t[1] + j));
      }
    }
  }
  return l;
}

FlareAtlasLevel flare_atlas_reduce(const FlareAtlasLevel& f) {
  if (f.width % 2 || f.height % 2) throw std::invalid_argument("flare_atlas_reduce: odd level size");
  FlareAtlasLevel l{f.width / 2, f.height / 2, {}};
  l.rgba.assign(size_t(l.width) * l.height * 4, 0.0);
  for (uint32_t y = 0; y < l.height; ++y) {
    for (uint32_t x = 0; x < l.width; ++x) {
      for (int c = 0; c < 4; ++c) {
        l.at(x, y)[c] = 0.25 * (f.at(2 * x, 2 * y)[c] + f.at(2 * x + 1, 2 * y)[c] + f.at(2 * x, 2 * y + 1)[c] +
                                f.at(2 * x + 1, 2 * y + 1)[c]);
      }
    }
  }
  return l;
}

FlareAtlas flare_atlas() {
  FlareAtlas a{flare_atlas_level0()};
  while (a.size() < GLINT_FLARE_ATLAS_LEVELS) a.push_back(flare_atlas_reduce(a.back()));
  return a;
}

GlintLodAtlas flare_lod_atlas() {
  return {float(GLINT_FLARE_ATLAS_WIDTH),
          float(GLINT_FLARE_ATLAS_HEIGHT),
          float(GLINT_FLARE_ATLAS_LEVELS),
          0.0f,
          1.0f,
          float(GLINT_FLARE_ATLAS_PADDING),
          GLINT_LOD_PADDING_CAP,
          0u};
}

FlareSprite flare_sprite(const GlintFlareInstance& in, uint32_t slot, const FlareConfig& c, uint32_t vw, uint32_t vh) {
  FlareSprite s;
  const double fields[] = {in.center_x_px, in.center_y_px, in.size_px, in.visible_fraction,
                           in.intensity,   in.color_r,     in.color_g, in.color_b};
  for (double f : fields) {
    if (!std::isfinite(f)) return s;
  }
  if (!(in.size_px > 0 && in.visible_fraction > 0 && in.intensity > 0)) return s;
  double cx = in.center_x_px, cy = in.center_y_px, ex = 0, ey = 0, weight = 0;
  bool tinted = false;
  if (slot == GLINT_FLARE_SLOT_MAIN) {
    s.tile = in.element < GLINT_FLARE_ELEMENT_COUNT ? in.element : GLINT_FLARE_ELEMENT_GLOW;
    ex = ey = GLINT_FLARE_MAIN_SCALE;
    weight = c.main_weight;
  } else if (slot == GLINT_FLARE_SLOT_STREAK) {
    s.tile = GLINT_FLARE_ELEMENT_STREAK;
    ex = c.streak_length;
    ey = GLINT_FLARE_STREAK_HEIGHT;
    weight = c.streak_weight;
    tinted = true;
  } else if (slot == GLINT_FLARE_SLOT_HALO) {
    s.tile = GLINT_FLARE_ELEMENT_HALO;
    ex = ey = GLINT_FLARE_HALO_SCALE;
    weight = c.halo_weight;
  } else if (slot == GLINT_FLARE_SLOT_STARBURST) {
    s.tile = GLINT_FLARE_ELEMENT_STARBURST;
    ex = ey = GLINT_FLARE_STARBURST_SCALE;
    weight = c.starburst_weight;
  } else {
    const uint32_t k = slot - GLINT_FLARE_SLOT_GHOST0;
    const double scales[5] = {GLINT_FLARE_GHOST_SCALE_0, GLINT_FLARE_GHOST_SCALE_1, GLINT_FLARE_GHOST_SCALE_2,
                              GLINT_FLARE_GHOST_SCALE_3, GLINT_FLARE_GHOST_SCALE_4};
    const double gains[5] = {GLINT_FLARE_GHOST_GAIN_0, GLINT_FLARE_GHOST_GAIN_1, GLINT_FLARE_GHOST_GAIN_2,
                             GLINT_FLARE_GHOST_GAIN_3, GLINT_FLARE_GHOST_GAIN_4};
    const double t = c.ghost_positions[k];
    s.tile = GLINT_FLARE_ELEMENT_GHOST;
    cx = in.center_x_px + (0.5 * vw - in.center_x_px) * t;
    cy = in.center_y_px + (0.5 * vh - in.center_y_px) * t;
    ex = ey = scales[k];
    weight = c.ghost_weight * gains[k];
    tinted = true;
  }
  if (!(weight > 0)) return s;
  s.width = ex * in.size_px * c.anamorphic_ratio;
  s.height = ey * in.size_px;
  s.lo_x = cx - 0.5 * s.width;
  s.lo_y = cy - 0.5 * s.height;
  const double colour[3] = {in.color_r, in.color_g, in.color_b};
  const double scale = double(in.intensity) * in.visible_fraction * c.intensity * weight;
  for (int ch = 0; ch < 3; ++ch) {
    s.rgb[ch] = std::max(colour[ch], 0.0) * scale * (tinted && c.tint ? c.tint_color[ch] : 1.0);
  }
  const auto tile = flare_tile(s.tile);
  GlintLodQuery q{float(1.0 / s.width), 0.0f,           0.0f,           float(1.0 / s.height),
                  float(tile[2]),       float(tile[3]), float(tile[0]), float(tile[1])};
  s.lod = lod(q, flare_lod_atlas());
  return s;
}

namespace {

// Bilinear clamp-to-edge at one level, with the bound for weights off by at most `delta` per axis:
// |d value / d weight| <= the range of the four taps, per axis.
void bilinear(const FlareAtlasLevel& l, double u, double v, double delta, double out[4], double bound[4]) {
  const double x = u * l.width - 0.5, y = v * l.height - 0.5;
  const double fx = std::floor(x), fy = std::floor(y);
  const double a = x - fx, b = y - fy;
  auto clampi = [](double i, uint32_t n) { return uint32_t(std::clamp(i, 0.0, double(n - 1))); };
  const uint32_t x0 = clampi(fx, l.width), x1 = clampi(fx + 1, l.width);
  const uint32_t y0 = clampi(fy, l.height), y1 = clampi(fy + 1, l.height);
  for (int c = 0; c < 4; ++c) {
    const double t00 = l.at(x0, y0)[c], t10 = l.at(x1, y0)[c], t01 = l.at(x0, y1)[c], t11 = l.at(x1, y1)[c];
    out[c] = (1 - a) * (1 - b) * t00 + a * (1 - b) * t10 + (1 - a) * b * t01 + a * b * t11;
    const double range = std::max({t00, t10, t01, t11}) - std::min({t00, t10, t01, t11});
    bound[c] = 2.0 * delta * range;
  }
}

}  // namespace

FlareSample flare_sample(const FlareAtlas& atlas, double u, double v, double lod, SamplerPrecision p) {
  FlareSample s;
  const double top = double(atlas.size() - 1);
  const double lambda = std::clamp(lod, 0.0, top);
  const double base = std::floor(lambda);
  const double f = lambda - base;
  // Weight error: the device's quantization step plus fp32 coordinates (about 2e-4 of a level-0
  // texel for this atlas: ulp(0.5) * 832 for the atlas UV, ulp(1) * 256 for the tile UV).
  const double delta = std::ldexp(1.0, -int(p.subtexel_bits)) + 2e-4;
  double v0[4], b0[4], v1[4], b1[4];
  bilinear(atlas[size_t(base)], u, v, delta, v0, b0);
  if (f > 0.0 && base < top) {
    bilinear(atlas[size_t(base) + 1], u, v, delta, v1, b1);
  } else {
    std::copy(v0, v0 + 4, v1);
    std::copy(b0, b0 + 4, b1);
  }
  const double mip_delta = std::ldexp(1.0, -int(p.mipmap_bits)) + 1e-5;  // + fp32 log2 of lambda
  for (int c = 0; c < 4; ++c) {
    s.rgba[c] = (1 - f) * v0[c] + f * v1[c];
    s.bound[c] = (1 - f) * b0[c] + f * b1[c] + mip_delta * std::fabs(v0[c] - v1[c]);
  }
  // Near an integer lambda the device may take the pair (base - 1, base) with weight ~1: the same
  // value in the limit, covered by the mip term of the neighbouring pair.
  if (base > 0 && f < 1e-4) {
    double vm[4], bm[4];
    bilinear(atlas[size_t(base) - 1], u, v, delta, vm, bm);
    for (int c = 0; c < 4; ++c) s.bound[c] += mip_delta * std::fabs(vm[c] - v0[c]);
  }
  return s;
}

FlareComposite flare_composite(const CpuImage& dst, const std::vector<GlintFlareInstance>& instances, uint32_t count,
                               const FlareConfig& config, const FlareAtlas& atlas, SamplerPrecision precision) {
  FlareComposite out;
  out.width = dst.width;
  out.height = dst.height;
  out.rgba.assign(dst.rgba.begin(), dst.rgba.end());
  out.bound.assign(out.rgba.size(), 0.0);
  out.count.assign(size_t(dst.width) * dst.height, 0);
  if (!config.enabled || config.intensity == 0.0f) return out;
  constexpr double kEdge = 2e-3;  // px: where fp32 positions may decide coverage either way
  const uint32_t n = std::min<uint32_t>(count, uint32_t(instances.size()));
  for (uint32_t i = 0; i < n; ++i) {
    for (uint32_t slot = 0; slot < GLINT_FLARE_SPRITES; ++slot) {
      const FlareSprite s = flare_sprite(instances[i], slot, config, dst.width, dst.height);
      if (!(s.width > 0)) continue;
      const auto tile = flare_tile(s.tile);
      const int x0 = int(std::clamp(std::floor(s.lo_x - 1), 0.0, double(dst.width)));
      const int x1 = int(std::clamp(std::ceil(s.lo_x + s.width + 1), 0.0, double(dst.width)));
      const int y0 = int(std::clamp(std::floor(s.lo_y - 1), 0.0, double(dst.height)));
      const int y1 = int(std::clamp(std::ceil(s.lo_y + s.height + 1), 0.0, double(dst.height)));
      for (int y = y0; y < y1; ++y) {
        for (int x = x0; x < x1; ++x) {
          const double px = x + 0.5, py = y + 0.5;
          const double dx = std::min(px - s.lo_x, s.lo_x + s.width - px);
          const double dy = std::min(py - s.lo_y, s.lo_y + s.height - py);
          const bool inside = px >= s.lo_x && py >= s.lo_y && px < s.lo_x + s.width && py < s.lo_y + s.height;
          const bool ambiguous = std::fabs(dx) < kEdge || std::fabs(dy) < kEdge;
          if (!inside && !ambiguous) continue;
          const double u = std::clamp((px - s.lo_x) / s.width, 0.0, 1.0);
          const double v = std::clamp((py - s.lo_y) / s.height, 0.0, 1.0);
          const double au = (tile[0] + u * tile[2]) / GLINT_FLARE_ATLAS_WIDTH;
          const double av = (tile[1] + v * tile[3]) / GLINT_FLARE_ATLAS_HEIGHT;
          const FlareSample t = flare_sample(atlas, au, av, s.lod, precision);
          const size_t p = size_t(y) * dst.width + x;
          for (int c = 0; c < 3; ++c) {
            const double add = s.rgb[c] * t.rgba[c];
            // fp32 scale of the colour (a few roundings) and of the sample
            const double b = s.rgb[c] * t.bound[c] + 1e-6 * std::fabs(add);
            if (ambiguous) {
              out.bound[p * 4 + c] += std::fabs(add) + b;
              if (inside) out.rgba[p * 4 + c] += add;
            } else {
              out.rgba[p * 4 + c] += add;
              out.bound[p * 4 + c] += b;
            }
          }
          if (inside) out.count[p]++;
        }
      }
    }
  }
  return out;
}

}  // namespace glint::reference
