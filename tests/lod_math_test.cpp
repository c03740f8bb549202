// Tests of glint's atlas-aware LOD on the CPU (docs/LOD.md): the C++ twin of the GLSL
// function (src/lod/lod_math.h, the same source as include/glint/gpu/lod.glsl) against the float64
// reference written from the Vulkan specification (tools/reference/lod_reference.h), the atlas
// cases a to g of docs/LOD.md, and the properties the specification implies. No Vulkan: the GPU's own sampler is
// compared in tests/lod_test.cpp. Random inputs come from std::mt19937 started from fixed values.
#include "lod/lod_math.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "reference/lod_reference.h"

namespace {

namespace lm = glint::lod_math;
namespace ref = glint::reference;

constexpr float kAtlas = 4096.0f;
constexpr float kAtlasLevels = 13.0f;  // 4096 -> 1
constexpr float kAnisoChoices[] = {1.0f, 2.0f, 4.0f, 16.0f};
constexpr double kTol = 1e-5;  // levels, twin vs reference (docs/LOD.md, "Float precision of the twin")

GlintLodQuery make_query(float dudx, float dvdx, float dudy, float dvdy, float w, float h, float off_x = 0.0f,
                         float off_y = 0.0f) {
  GlintLodQuery q{};
  q.dudx = dudx;
  q.dvdx = dvdx;
  q.dudy = dudy;
  q.dvdy = dvdy;
  q.tex_w = w;
  q.tex_h = h;
  q.off_x = off_x;
  q.off_y = off_y;
  return q;
}

GlintLodAtlas make_atlas(float w, float h, float levels, float bias = 0.0f, uint32_t flags = 0u, float max_aniso = 1.0f,
                         float padding = 0.0f) {
  GlintLodAtlas a{};
  a.atlas_w = w;
  a.atlas_h = h;
  a.levels = levels;
  a.bias = bias;
  a.max_aniso = max_aniso;
  a.padding = padding;
  a.flags = flags;
  return a;
}

GlintLodQuery scaled(GlintLodQuery q, float s) {
  q.dudx *= s;
  q.dvdx *= s;
  q.dudy *= s;
  q.dvdy *= s;
  return q;
}

std::string describe(const GlintLodQuery& q, const GlintLodAtlas& a) {
  char buf[512];
  std::snprintf(buf, sizeof buf,
                "query d=(%.9g, %.9g, %.9g, %.9g) tex=%gx%g off=(%g, %g); atlas %gx%g levels=%g bias=%.9g "
                "max_aniso=%g padding=%g flags=%u",
                q.dudx, q.dvdx, q.dudy, q.dvdy, q.tex_w, q.tex_h, q.off_x, q.off_y, a.atlas_w, a.atlas_h, a.levels,
                a.bias, a.max_aniso, a.padding, a.flags);
  return buf;
}

// A derivative over many octaves, either sign, sometimes exactly 0.
float random_derivative(std::mt19937& rng) {
  std::uniform_real_distribution<double> octave(-24.0, 6.0);
  std::bernoulli_distribution zero(0.08), negative(0.5);
  if (zero(rng)) return 0.0f;
  const double v = std::exp2(octave(rng));
  return float(negative(rng) ? -v : v);
}

// A tile size 1..4096, spread evenly over octaves.
float random_size(std::mt19937& rng) {
  std::uniform_real_distribution<double> octave(0.0, 12.0);
  return float(std::clamp(std::round(std::exp2(octave(rng))), 1.0, 4096.0));
}

GlintLodQuery random_query(std::mt19937& rng) {
  GlintLodQuery q{};
  q.dudx = random_derivative(rng);
  q.dvdx = random_derivative(rng);
  q.dudy = random_derivative(rng);
  q.dvdy = random_derivative(rng);
  q.tex_w = random_size(rng);
  q.tex_h = random_size(rng);
  q.off_x = float(std::uniform_int_distribution<int>(0, int(kAtlas - q.tex_w))(rng));
  q.off_y = float(std::uniform_int_distribution<int>(0, int(kAtlas - q.tex_h))(rng));
  return q;
}

GlintLodAtlas random_atlas(std::mt19937& rng) {
  uint32_t flags = 0u;
  if (std::bernoulli_distribution(0.5)(rng)) flags |= GLINT_LOD_ANISOTROPIC;
  if (std::bernoulli_distribution(0.4)(rng)) flags |= GLINT_LOD_PADDING_CAP;
  const float levels = float(std::uniform_int_distribution<int>(1, 13)(rng));
  const float bias = float(std::uniform_real_distribution<double>(-2.0, 2.0)(rng));
  const float max_aniso = kAnisoChoices[std::uniform_int_distribution<int>(0, 3)(rng)];
  const float padding = float(std::uniform_int_distribution<int>(0, 64)(rng));
  return make_atlas(kAtlas, kAtlas, levels, bias, flags, max_aniso, padding);
}

// What the sampler itself computes for the same footprint when the shader samples the atlas at
// atlas UV = (off + sub_uv * size) / atlas: the chain rule gives d(atlas_u)/dx = du/dx * w / W,
// and the sampler scales by the atlas size W (docs/LOD.md). Float64, no clamp.
double sampler_view_unclamped(const GlintLodQuery& q, const GlintLodAtlas& a) {
  const double W = a.atlas_w, H = a.atlas_h;
  GlintLodQuery atlas_q =
      make_query(float(q.dudx * double(q.tex_w) / W), float(q.dvdx * double(q.tex_h) / H),
                 float(q.dudy * double(q.tex_w) / W), float(q.dvdy * double(q.tex_h) / H), a.atlas_w, a.atlas_h);
  GlintLodAtlas whole = a;
  whole.flags &= ~GLINT_LOD_PADDING_CAP;
  return ref::lod_unclamped(atlas_q, whole);
}

// ---------------------------------------------------------------------------------------------
// CPU simulation of a padded atlas: a base level of doubles, a mip chain by 2x2 box averaging,
// bilinear sampling with clamp-to-edge at the atlas border, trilinear between levels. Blends use
// a + t * (b - a), so blending equal values is exact and "no bleed" can be checked with ==.

struct Rect {
  int x, y, w, h;
};

struct MipChain {
  std::vector<int> w, h;
  std::vector<std::vector<double>> texels;

  double at(int level, int x, int y) const {
    x = std::clamp(x, 0, w[level] - 1);
    y = std::clamp(y, 0, h[level] - 1);
    return texels[level][size_t(y) * w[level] + x];
  }
};

double lerp(double a, double b, double t) { return a + t * (b - a); }

constexpr double kColourA = 0.25, kColourB = 0.75, kBackground = 0.5;

// Tile A with `pad` texels of its own colour around it, tile B right of A's padding with its own
// padding, background elsewhere. The atlas is size x size, a power of two.
MipChain build_atlas(int size, const Rect& a_tile, const Rect& b_tile, int pad) {
  MipChain m;
  std::vector<double> base(size_t(size) * size, kBackground);
  auto fill = [&](const Rect& r, double c) {
    for (int y = std::max(r.y - pad, 0); y < std::min(r.y + r.h + pad, size); ++y)
      for (int x = std::max(r.x - pad, 0); x < std::min(r.x + r.w + pad, size); ++x) base[size_t(y) * size + x] = c;
  };
  fill(a_tile, kColourA);
  fill(b_tile, kColourB);
  m.w.push_back(size);
  m.h.push_back(size);
  m.texels.push_back(std::move(base));
  while (m.w.back() > 1) {
    const int pw = m.w.back(), nw = pw / 2;
    const std::vector<double>& prev = m.texels.back();
    std::vector<double> next(size_t(nw) * nw);
    for (int y = 0; y < nw; ++y)
      for (int x = 0; x < nw; ++x)
        next[size_t(y) * nw + x] = (prev[size_t(2 * y) * pw + 2 * x] + prev[size_t(2 * y) * pw + 2 * x + 1] +
                                    prev[size_t(2 * y + 1) * pw + 2 * x] + prev[size_t(2 * y + 1) * pw + 2 * x + 1]) /
                                   4.0;
    m.w.push_back(nw);
    m.h.push_back(nw);
    m.texels.push_back(std::move(next));
  }
  return m;
}

// Bilinear sample of `level` at a position given in level-0 texel units (texel centres at +0.5).
double bilinear(const MipChain& m, int level, double px, double py) {
  const double s = std::ldexp(1.0, -level);
  const double x = px * s - 0.5, y = py * s - 0.5;
  const int x0 = int(std::floor(x)), y0 = int(std::floor(y));
  const double fx = x - x0, fy = y - y0;
  const double top = lerp(m.at(level, x0, y0), m.at(level, x0 + 1, y0), fx);
  const double bottom = lerp(m.at(level, x0, y0 + 1), m.at(level, x0 + 1, y0 + 1), fx);
  return lerp(top, bottom, fy);
}

double trilinear(const MipChain& m, double lambda, double px, double py) {
  const int l0 = int(std::floor(lambda));
  const double f = lambda - l0;
  const double c0 = bilinear(m, l0, px, py);
  if (f == 0.0) return c0;
  return lerp(c0, bilinear(m, l0 + 1, px, py), f);
}

// Sample points on tile A's border: its edges and its edge texel centres, every half texel.
std::vector<std::pair<double, double>> border_points(const Rect& r) {
  std::vector<std::pair<double, double>> pts;
  const double xs[] = {double(r.x), r.x + 0.5, r.x + r.w - 0.5, double(r.x + r.w)};
  const double ys[] = {double(r.y), r.y + 0.5, r.y + r.h - 0.5, double(r.y + r.h)};
  for (double x : xs)
    for (double y = r.y; y <= r.y + r.h; y += 0.5) pts.emplace_back(x, y);
  for (double y : ys)
    for (double x = r.x; x <= r.x + r.w; x += 0.5) pts.emplace_back(x, y);
  return pts;
}

// The anisotropic footprint: probes along the major axis, up to rho_max / 2 texels each side.
std::vector<std::pair<double, double>> footprint_offsets(const GlintLodQuery& q, bool aniso) {
  std::vector<std::pair<double, double>> offs{{0.0, 0.0}};
  if (!aniso) return offs;
  const double ax = double(q.dudx) * q.tex_w, ay = double(q.dvdx) * q.tex_h;
  const double bx = double(q.dudy) * q.tex_w, by = double(q.dvdy) * q.tex_h;
  const bool x_major = std::hypot(ax, ay) >= std::hypot(bx, by);
  const double mx = x_major ? ax : bx, my = x_major ? ay : by;  // full major-axis vector, length rho_max
  for (int i = -8; i <= 8; ++i) {
    const double t = i / 16.0;  // -1/2 .. 1/2
    offs.emplace_back(t * mx, t * my);
  }
  return offs;
}

// True when every probe of the footprint around every border point of A returns A's colour.
bool no_bleed(const MipChain& m, double lambda, const Rect& a_tile, const GlintLodQuery& q, bool aniso) {
  const auto offs = footprint_offsets(q, aniso);
  for (const auto& [px, py] : border_points(a_tile))
    for (const auto& [ox, oy] : offs)
      if (trilinear(m, lambda, px + ox, py + oy) != kColourA) return false;
  return true;
}

// ---------------------------------------------------------------------------------------------

TEST(LodMath, TwinMatchesFloat64Reference) {
  std::mt19937 rng(20240404u);
  int interior = 0, failures = 0;
  double worst = 0.0;
  constexpr int kCount = 50000;
  for (int i = 0; i < kCount; ++i) {
    const GlintLodQuery q = random_query(rng);
    const GlintLodAtlas a = random_atlas(rng);
    const double twin = lm::glint_lod(q, a);
    const double exact = ref::lod(q, a);
    const double err = std::fabs(twin - exact);
    worst = std::max(worst, err);
    if (exact > 0.0 && exact < a.levels - 1.0) ++interior;
    if (!(err <= kTol) && ++failures <= 10)
      ADD_FAILURE() << "twin " << twin << " reference " << exact << " for " << describe(q, a);
    // The scale factors themselves agree to float precision.
    EXPECT_NEAR(lm::glint_lod_rho_x(q), ref::lod_rho_x(q), 1e-6 * ref::lod_rho_x(q) + 1e-30);
    EXPECT_NEAR(lm::glint_lod_rho_y(q), ref::lod_rho_y(q), 1e-6 * ref::lod_rho_y(q) + 1e-30);
  }
  EXPECT_EQ(failures, 0);
  EXPECT_GT(interior, kCount / 4) << "too few queries inside (0, levels - 1) to test anything";
  RecordProperty("worst_error_levels", std::to_string(worst));
  std::printf("twin vs float64 reference: worst |difference| %.3g levels over %d queries (%d unclamped)\n", worst,
              kCount, interior);
}

// Atlas cases a and b: a 16x16 and a 2048x2048 tile anywhere in a 4096x4096 atlas get the level of
// a standalone texture of the same size, and the level the sampler computes from atlas UV.
TEST(LodMath, AtlasCaseAB_TileInAtlasMatchesStandaloneTexture) {
  std::mt19937 rng(1601u);
  for (float size : {16.0f, 2048.0f}) {
    const float standalone_levels = float(std::log2(size)) + 1.0f;
    int compared = 0;
    for (int i = 0; i < 3000; ++i) {
      for (uint32_t flags : {0u, uint32_t(GLINT_LOD_ANISOTROPIC)}) {
        GlintLodQuery q = make_query(random_derivative(rng), random_derivative(rng), random_derivative(rng),
                                     random_derivative(rng), size, size);
        q.off_x = float(std::uniform_int_distribution<int>(0, int(kAtlas - size))(rng));
        q.off_y = float(std::uniform_int_distribution<int>(0, int(kAtlas - size))(rng));
        const float max_aniso = kAnisoChoices[i % 4];
        const GlintLodAtlas atlas = make_atlas(kAtlas, kAtlas, kAtlasLevels, 0.0f, flags, max_aniso);
        const GlintLodQuery alone_q = make_query(q.dudx, q.dvdx, q.dudy, q.dvdy, size, size);
        const GlintLodAtlas alone = make_atlas(size, size, standalone_levels, 0.0f, flags, max_aniso);
        const double in_atlas = lm::glint_lod_unclamped(q, atlas);
        if (!(in_atlas > -60.0)) continue;  // zero footprint: no level to compare
        EXPECT_NEAR(in_atlas, lm::glint_lod_unclamped(alone_q, alone), kTol) << describe(q, atlas);
        EXPECT_NEAR(in_atlas, sampler_view_unclamped(q, atlas), kTol) << describe(q, atlas);
        // Below the standalone texture's own top level the clamped levels agree too.
        if (in_atlas < standalone_levels - 1.0f) {
          EXPECT_NEAR(lm::glint_lod(q, atlas), lm::glint_lod(alone_q, alone), kTol) << describe(q, atlas);
          ++compared;
        }
      }
    }
    EXPECT_GT(compared, 1000) << size;
  }
  // Hand values: 4 tile texels per pixel is level 2 whatever the tile's size and place.
  EXPECT_FLOAT_EQ(
      lm::glint_lod(make_query(4.0f / 16, 0, 0, 4.0f / 16, 16, 16, 4080, 0), make_atlas(kAtlas, kAtlas, kAtlasLevels)),
      2.0f);
  EXPECT_FLOAT_EQ(lm::glint_lod(make_query(4.0f / 2048, 0, 0, 4.0f / 2048, 2048, 2048, 2048, 2048),
                                make_atlas(kAtlas, kAtlas, kAtlasLevels)),
                  2.0f);
}

// Atlas case c: 256x512 agrees with 256x256 when the derivatives are only in u (in both screen
// directions: du/dy scales by the width, not the height), and is one level higher when they are
// only in v.
TEST(LodMath, AtlasCaseC_NonSquareScalesUByWidthAndVByHeight) {
  std::mt19937 rng(2560512u);
  const GlintLodAtlas atlas = make_atlas(kAtlas, kAtlas, kAtlasLevels);
  for (int i = 0; i < 3000; ++i) {
    const float dx = random_derivative(rng), dy = random_derivative(rng);
    if (dx == 0.0f && dy == 0.0f) continue;
    const GlintLodQuery tall_u = make_query(dx, 0, dy, 0, 256, 512, 1024, 512);
    const GlintLodQuery square_u = make_query(dx, 0, dy, 0, 256, 256, 3000, 17);
    EXPECT_EQ(lm::glint_lod_unclamped(tall_u, atlas), lm::glint_lod_unclamped(square_u, atlas))
        << describe(tall_u, atlas);
    EXPECT_EQ(lm::glint_lod(tall_u, atlas), lm::glint_lod(square_u, atlas)) << describe(tall_u, atlas);
    EXPECT_NEAR(ref::lod(tall_u, atlas), ref::lod(square_u, atlas), 1e-12);
    const GlintLodQuery tall_v = make_query(0, dx, 0, dy, 256, 512, 1024, 512);
    const GlintLodQuery square_v = make_query(0, dx, 0, dy, 256, 256, 3000, 17);
    EXPECT_NEAR(lm::glint_lod_unclamped(tall_v, atlas) - lm::glint_lod_unclamped(square_v, atlas), 1.0, kTol)
        << describe(tall_v, atlas);
  }
  // Derivative only along u in screen y: 1/256 per pixel is one texel per pixel, level 0 unclamped.
  EXPECT_FLOAT_EQ(lm::glint_lod_unclamped(make_query(0, 0, 1.0f / 256, 0, 256, 512), atlas), 0.0f);
  EXPECT_FLOAT_EQ(lm::glint_lod_unclamped(make_query(0, 0, 0, 1.0f / 256, 256, 512), atlas), 1.0f);
}

// Atlas case d: a tile at the atlas corner (offset = atlas - size) gets the same level as at the
// origin; one texel further it is outside the atlas and falls back to level 0.
TEST(LodMath, AtlasCaseD_TileAtAtlasCorner) {
  std::mt19937 rng(4095u);
  for (int i = 0; i < 3000; ++i) {
    const GlintLodAtlas atlas = random_atlas(rng);
    GlintLodQuery q = random_query(rng);
    GlintLodQuery corner = q, origin = q;
    corner.off_x = kAtlas - q.tex_w;
    corner.off_y = kAtlas - q.tex_h;
    origin.off_x = origin.off_y = 0.0f;
    EXPECT_EQ(lm::glint_lod(corner, atlas), lm::glint_lod(origin, atlas)) << describe(corner, atlas);
    EXPECT_EQ(lm::glint_lod(corner, atlas), lm::glint_lod(q, atlas)) << describe(corner, atlas);
    EXPECT_NEAR(lm::glint_lod(corner, atlas), ref::lod(corner, atlas), kTol) << describe(corner, atlas);
    GlintLodQuery outside = corner;
    outside.off_x += 1.0f;
    EXPECT_EQ(lm::glint_lod(outside, atlas), 0.0f);
    EXPECT_EQ(ref::lod(outside, atlas), 0.0);
  }
}

// Atlas case e: adjacent tiles with P texels of padding. At the level the function chooses (with
// GLINT_LOD_PADDING_CAP), sampling a box-filtered mip chain bilinearly at tile A's border returns
// exactly A's colour; one level above the cap does bleed for some layouts.
TEST(LodMath, AtlasCaseE_AdjacentTilesNoBleedAtChosenLevel) {
  constexpr int kSize = 256;
  const float levels = 9.0f;
  std::mt19937 rng(777u);
  int layouts = 0, bleed_above_cap = 0, capped = 0;
  for (int pad : {2, 3, 4, 6, 8, 12, 16, 24, 32}) {
    int bleed_above_cap_this_pad = 0;
    const bool power_of_two = (pad & (pad - 1)) == 0;
    for (int tw : {5, 8, 13, 16, 24, 31}) {
      for (int shift = 0; shift < 8; shift += 3) {
        const Rect a_tile{pad + shift, pad + 2 * shift, tw, tw + 3};
        const Rect b_tile{a_tile.x + a_tile.w + 2 * pad, a_tile.y, 20, 20};
        const MipChain mips = build_atlas(kSize, a_tile, b_tile, pad);
        ++layouts;
        for (int trial = 0; trial < 12; ++trial) {
          const bool aniso = trial % 2 == 1;
          // Large footprints (cap decides) and random ones (lambda may be below the cap).
          const double texels = trial < 4 ? std::exp2(std::uniform_real_distribution<double>(6.0, 12.0)(rng))
                                          : std::exp2(std::uniform_real_distribution<double>(-2.0, 6.0)(rng));
          const double angle = std::uniform_real_distribution<double>(0.0, 6.283185307179586)(rng);
          const double ratio = std::exp2(std::uniform_real_distribution<double>(0.0, 4.0)(rng));
          GlintLodQuery q = make_query(float(texels * std::cos(angle) / tw), float(texels * std::sin(angle) / a_tile.h),
                                       float(-texels / ratio * std::sin(angle) / tw),
                                       float(texels / ratio * std::cos(angle) / a_tile.h), float(tw), float(a_tile.h),
                                       float(a_tile.x), float(a_tile.y));
          const GlintLodAtlas atlas =
              make_atlas(kSize, kSize, levels, 0.0f, GLINT_LOD_PADDING_CAP | (aniso ? GLINT_LOD_ANISOTROPIC : 0u), 4.0f,
                         float(pad));
          const double cap = lm::glint_lod_padding_cap(q, atlas);
          const double reach = aniso ? 0.5 * std::max(ref::lod_rho_x(q), ref::lod_rho_y(q)) : 0.0;
          if (pad - reach < 2.0) continue;  // the footprint alone is longer than the padding
          const double lambda = lm::glint_lod(q, atlas);
          EXPECT_NEAR(lambda, ref::lod(q, atlas), kTol) << describe(q, atlas);
          EXPECT_LE(lambda, cap);
          if (lambda == cap) ++capped;
          EXPECT_TRUE(no_bleed(mips, lambda, a_tile, q, aniso))
              << "bleed at the chosen level " << lambda << " (cap " << cap << ") " << describe(q, atlas);
          if (!aniso && cap + 1.0 <= levels - 1.0 && !no_bleed(mips, cap + 1.0, a_tile, q, false)) {
            ++bleed_above_cap;
            ++bleed_above_cap_this_pad;
          }
        }
      }
    }
    // The rule 2^(L+1) <= P is exact for P a power of two >= 4 (one level more reaches past the
    // padding); for other P it leaves slack (a tap really reaches 1.5 texels, not 2).
    if (power_of_two && pad >= 4) {
      EXPECT_GT(bleed_above_cap_this_pad, 0) << "padding " << pad << ": one level above the cap never bleeds";
    }
    std::printf("padding %2d: %d queries bleed one level above the cap\n", pad, bleed_above_cap_this_pad);
  }
  EXPECT_GT(capped, layouts) << "too few queries where the cap decided";
  EXPECT_GT(bleed_above_cap, 0);
  std::printf("adjacent tiles: %d layouts, %d capped queries, %d bleed one level above the cap\n", layouts, capped,
              bleed_above_cap);
}

// Atlas case f, REPEAT inside a tile: the shader passes derivatives of the unwrapped UV, and the
// level shows no jump across a seam; derivatives of fract(uv) (finite differences) would spike.
TEST(LodMath, AtlasCaseF_RepeatSeamsDoNotSpike) {
  const GlintLodAtlas atlas = make_atlas(kAtlas, kAtlas, kAtlasLevels);
  const float w = 64.0f, h = 32.0f;
  // u(x) = (a x + b) / (c x + 1): a perspective ramp repeating many times across 400 pixels.
  const double a = 0.06, b = 0.3, c = 0.002, v_rate = 0.01;
  auto u_of = [&](double x) { return (a * x + b) / (c * x + 1.0); };
  auto dudx_of = [&](double x) { return (a - b * c) / ((c * x + 1.0) * (c * x + 1.0)); };
  double max_step_unwrapped = 0.0, max_step_fract = 0.0;
  int seams = 0;
  double prev_unwrapped = 0.0, prev_fract = 0.0;
  for (int x = 0; x < 400; ++x) {
    const GlintLodQuery unwrapped = make_query(float(dudx_of(x)), float(v_rate), 0.0f, float(v_rate), w, h, 128, 256);
    const double fd = (u_of(x + 1) - std::floor(u_of(x + 1))) - (u_of(x) - std::floor(u_of(x)));
    const GlintLodQuery wrapped = make_query(float(fd), float(v_rate), 0.0f, float(v_rate), w, h, 128, 256);
    const double l_unwrapped = lm::glint_lod(unwrapped, atlas);
    const double l_fract = lm::glint_lod(wrapped, atlas);
    EXPECT_NEAR(l_unwrapped, ref::lod(unwrapped, atlas), kTol);
    if (std::floor(u_of(x + 1)) != std::floor(u_of(x))) ++seams;
    if (x > 0) {
      max_step_unwrapped = std::max(max_step_unwrapped, std::fabs(l_unwrapped - prev_unwrapped));
      max_step_fract = std::max(max_step_fract, std::fabs(l_fract - prev_fract));
    }
    prev_unwrapped = l_unwrapped;
    prev_fract = l_fract;
  }
  EXPECT_GE(seams, 10);
  EXPECT_LT(max_step_unwrapped, 0.02) << "the level jumps between neighbouring pixels";
  EXPECT_GT(max_step_fract, 3.0) << "fract(uv) differences should spike at seams (the failure this avoids)";
}

// Atlas case g, CLAMP_TO_EDGE: the shader clamps the tile UV to [0, 1], so a minified footprint
// sits on the tile's edge. With the padding cap the level stays where the footprint is inside the
// padding (no bleed); without it the level goes to the top and the edge takes the neighbours'
// colours.
TEST(LodMath, AtlasCaseG_ClampToEdgeRespectsPadding) {
  constexpr int kSize = 256;
  const float levels = 9.0f;
  for (int pad : {2, 4, 5, 8, 16}) {
    const Rect a_tile{pad + 1, pad + 1, 24, 16};
    const Rect b_tile{a_tile.x + a_tile.w + 2 * pad, a_tile.y, 24, 16};
    const MipChain mips = build_atlas(kSize, a_tile, b_tile, pad);
    // 1000 texels per pixel along u, 700 along v: strongly minified.
    const GlintLodQuery q = make_query(1000.0f / 24, 0.0f, 0.0f, 700.0f / 16, 24, 16, float(a_tile.x), float(a_tile.y));
    const GlintLodAtlas capped = make_atlas(kSize, kSize, levels, 0.0f, GLINT_LOD_PADDING_CAP, 1.0f, float(pad));
    const GlintLodAtlas uncapped = make_atlas(kSize, kSize, levels, 0.0f, 0u, 1.0f, float(pad));
    const double expected_cap = std::floor(std::log2(double(pad))) - 1.0;
    EXPECT_EQ(lm::glint_lod(q, capped), float(expected_cap)) << "padding " << pad;
    EXPECT_EQ(ref::lod(q, capped), expected_cap);
    EXPECT_EQ(lm::glint_lod(q, uncapped), levels - 1.0f);
    // Clamped UVs: sample points on the edges and corners of the tile.
    EXPECT_TRUE(no_bleed(mips, lm::glint_lod(q, capped), a_tile, q, false)) << "padding " << pad;
    EXPECT_FALSE(no_bleed(mips, lm::glint_lod(q, uncapped), a_tile, q, false)) << "padding " << pad;
  }
}

// Doubling every derivative adds exactly one level (isotropic and anisotropic, below the clamps).
TEST(LodMath, DoublingDerivativesAddsOneLevel) {
  std::mt19937 rng(2u);
  int checked = 0;
  for (int i = 0; i < 20000; ++i) {
    const GlintLodQuery q = random_query(rng);
    GlintLodAtlas a = random_atlas(rng);
    a.flags &= ~GLINT_LOD_PADDING_CAP;
    const double l1 = lm::glint_lod(q, a), l2 = lm::glint_lod(scaled(q, 2.0f), a);
    const double u1 = ref::lod_unclamped(q, a);
    EXPECT_NEAR(lm::glint_lod_unclamped(scaled(q, 2.0f), a) - lm::glint_lod_unclamped(q, a), u1 > -1e9 ? 1.0 : 0.0,
                kTol)
        << describe(q, a);
    if (u1 > 1e-4 && u1 + 1.0 < a.levels - 1.0 - 1e-4) {
      EXPECT_NEAR(l2 - l1, 1.0, kTol) << describe(q, a);
      ++checked;
    }
  }
  EXPECT_GT(checked, 2000);
}

// Swapping the x and y derivatives changes nothing.
TEST(LodMath, SymmetricInScreenXAndY) {
  std::mt19937 rng(3u);
  for (int i = 0; i < 20000; ++i) {
    const GlintLodQuery q = random_query(rng);
    const GlintLodAtlas a = random_atlas(rng);
    const GlintLodQuery s = make_query(q.dudy, q.dvdy, q.dudx, q.dvdx, q.tex_w, q.tex_h, q.off_x, q.off_y);
    EXPECT_EQ(lm::glint_lod(q, a), lm::glint_lod(s, a)) << describe(q, a);
    EXPECT_NEAR(ref::lod(q, a), ref::lod(s, a), 1e-12) << describe(q, a);
  }
}

// Anisotropic LOD: rho_min = 0 gives eta = max_aniso; both zero give level 0 (no NaN); ratios 1
// to 32 give lambda = log2(rho_max / min(ratio, max_aniso)), for any orientation.
TEST(LodMath, AnisotropicCases) {
  const GlintLodAtlas iso = make_atlas(kAtlas, kAtlas, kAtlasLevels);
  for (float max_aniso : kAnisoChoices) {
    const GlintLodAtlas an = make_atlas(kAtlas, kAtlas, kAtlasLevels, 0.0f, GLINT_LOD_ANISOTROPIC, max_aniso);
    // rho_min = 0: a line footprint of 256 texels.
    const GlintLodQuery line = make_query(1.0f, 0.0f, 0.0f, 0.0f, 256, 128, 512, 512);
    EXPECT_NEAR(lm::glint_lod(line, an), 8.0 - std::log2(max_aniso), kTol);
    EXPECT_NEAR(ref::lod(line, an), 8.0 - std::log2(max_aniso), 1e-12);
    EXPECT_FLOAT_EQ(lm::glint_lod(line, iso), 8.0f);
    // Both zero.
    const GlintLodQuery point = make_query(0.0f, 0.0f, -0.0f, 0.0f, 256, 128, 512, 512);
    for (float bias : {-2.0f, 0.0f, 1.5f}) {
      GlintLodAtlas biased = an;
      biased.bias = bias;
      const float l = lm::glint_lod(point, biased);
      EXPECT_FALSE(std::isnan(l));
      EXPECT_EQ(l, 0.0f);
      EXPECT_EQ(ref::lod(point, biased), 0.0);
    }
    // Ratios 1 .. 32, rotated footprints, rho_max = 64 texels.
    std::mt19937 rng(uint32_t(max_aniso * 100));
    for (int step = 0; step <= 40; ++step) {
      const double ratio = std::exp2(step / 8.0);  // 1 .. 32
      const double angle = std::uniform_real_distribution<double>(0.0, 6.283185307179586)(rng);
      const double major = 64.0, minor = major / ratio;
      const bool x_major = step % 2 == 0;
      const double mx = x_major ? major : minor, my = x_major ? minor : major;
      const GlintLodQuery q =
          make_query(float(mx * std::cos(angle) / 200), float(mx * std::sin(angle) / 100),
                     float(-my * std::sin(angle) / 200), float(my * std::cos(angle) / 100), 200, 100, 7, 9);
      const double expected = std::log2(major / std::min(ratio, double(max_aniso)));
      EXPECT_NEAR(lm::glint_lod(q, an), expected, kTol) << "ratio " << ratio << " max_aniso " << max_aniso;
      EXPECT_NEAR(ref::lod(q, an), expected, 1e-6) << "ratio " << ratio << " max_aniso " << max_aniso;
      EXPECT_NEAR(lm::glint_lod(q, iso), std::log2(major), kTol);
    }
  }
}

// The padding cap is the largest L with 2^(L+1) + reach <= padding (reach = rho_max / 2 with
// anisotropy, the major axis of the footprint), and 0 when none fits.
TEST(LodMath, PaddingCapCoversAnisotropicMajorAxis) {
  std::mt19937 rng(5u);
  for (int i = 0; i < 20000; ++i) {
    const GlintLodQuery q = random_query(rng);
    GlintLodAtlas a = random_atlas(rng);
    a.padding = float(std::uniform_real_distribution<double>(0.0, 300.0)(rng));
    if (i % 3 == 0) a.padding = std::round(a.padding);
    const bool aniso = (a.flags & GLINT_LOD_ANISOTROPIC) != 0u;
    const double reach = aniso ? 0.5 * std::max(ref::lod_rho_x(q), ref::lod_rho_y(q)) : 0.0;
    const double cap = lm::glint_lod_padding_cap(q, a);
    EXPECT_EQ(cap, std::floor(cap));
    if (a.padding - reach >= 2.0 + 1e-3) {
      EXPECT_LE(std::exp2(cap + 1.0) + reach, a.padding + 1e-3) << describe(q, a);
      EXPECT_GT(std::exp2(cap + 2.0) + reach, a.padding - 1e-3) << describe(q, a);
    } else if (a.padding - reach < 2.0 - 1e-3) {
      EXPECT_EQ(cap, 0.0) << describe(q, a);
    }
    if (std::fabs(a.padding - reach - std::exp2(std::round(std::log2(std::max(a.padding - reach, 1.0))))) > 1e-3) {
      EXPECT_EQ(cap, ref::lod_padding_cap(q, a)) << describe(q, a);
    }
  }
  // The isotropic cap ignores the footprint: aniso probes at the isotropic cap bleed for a long
  // footprint, at the anisotropic cap they do not.
  constexpr int kSize = 256, kPad = 16;
  const Rect a_tile{kPad + 3, kPad, 32, 32};
  const Rect b_tile{a_tile.x + a_tile.w + 2 * kPad, a_tile.y, 32, 32};
  const MipChain mips = build_atlas(kSize, a_tile, b_tile, kPad);
  const GlintLodQuery q = make_query(24.0f / 32, 0.0f, 0.0f, 0.5f / 32, 32, 32, kPad + 3, kPad);  // rho_max = 24
  const GlintLodAtlas an =
      make_atlas(kSize, kSize, 9, 0.0f, GLINT_LOD_ANISOTROPIC | GLINT_LOD_PADDING_CAP, 16.0f, float(kPad));
  GlintLodAtlas iso_cap = an;
  iso_cap.flags = GLINT_LOD_PADDING_CAP;
  EXPECT_EQ(lm::glint_lod_padding_cap(q, an), 1.0f);       // 2^2 + 12 <= 16 < 2^3 + 12
  EXPECT_EQ(lm::glint_lod_padding_cap(q, iso_cap), 3.0f);  // 2^4 <= 16
  EXPECT_TRUE(no_bleed(mips, lm::glint_lod_padding_cap(q, an), a_tile, q, true));
  EXPECT_FALSE(no_bleed(mips, lm::glint_lod_padding_cap(q, iso_cap), a_tile, q, true));
}

// Every path ends in [0, levels - 1], never NaN, and invalid input gives level 0.
TEST(LodMath, EveryPathClampsAndInvalidInputGivesLevelZero) {
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  const float specials[] = {nan, inf, -inf, 0.0f, -1.0f, 0.5f, 1e30f, -1e30f, 5000.0f};
  std::mt19937 rng(6u);
  for (int i = 0; i < 40000; ++i) {
    GlintLodQuery q = random_query(rng);
    GlintLodAtlas a = random_atlas(rng);
    // Break one or two fields half of the time.
    for (int k = 0; k < 2 && std::bernoulli_distribution(0.5)(rng); ++k) {
      const float v = specials[std::uniform_int_distribution<int>(0, 8)(rng)];
      switch (std::uniform_int_distribution<int>(0, 13)(rng)) {
        case 0:
          q.dudx = v;
          break;
        case 1:
          q.dvdx = v;
          break;
        case 2:
          q.dudy = v;
          break;
        case 3:
          q.dvdy = v;
          break;
        case 4:
          q.tex_w = v;
          break;
        case 5:
          q.tex_h = v;
          break;
        case 6:
          q.off_x = v;
          break;
        case 7:
          q.off_y = v;
          break;
        case 8:
          a.atlas_w = v;
          break;
        case 9:
          a.atlas_h = v;
          break;
        case 10:
          a.levels = v;
          break;
        case 11:
          a.bias = v;
          break;
        case 12:
          a.padding = v;
          break;
        default:
          a.levels = std::floor(std::fabs(v));
          break;
      }
    }
    const float l = lm::glint_lod(q, a);
    const double r = ref::lod(q, a);
    ASSERT_FALSE(std::isnan(l)) << describe(q, a);
    ASSERT_FALSE(std::isnan(r)) << describe(q, a);
    const double top = std::isfinite(a.levels) ? std::max(double(a.levels) - 1.0, 0.0) : 0.0;
    EXPECT_GE(l, 0.0f) << describe(q, a);
    EXPECT_LE(l, top) << describe(q, a);
    EXPECT_GE(r, 0.0);
    EXPECT_LE(r, top);
    if (!ref::lod_valid(q, a)) {
      EXPECT_EQ(l, 0.0f) << describe(q, a);
      EXPECT_EQ(r, 0.0);
    } else if (a.levels <= 64.0f && std::fabs(a.bias) <= 16.0f && ref::lod_rho_x(q) < 1e18 &&
               ref::lod_rho_y(q) < 1e18) {
      // Inside float's comfortable range (a mip chain has at most 33 levels, maxSamplerLodBias is
      // small, and scale factors near 2^64 overflow float squares) the twin matches the reference.
      EXPECT_NEAR(l, r, kTol) << describe(q, a);
    }
  }
  // The named invalid inputs.
  const GlintLodAtlas atlas = make_atlas(kAtlas, kAtlas, kAtlasLevels, 0.5f, GLINT_LOD_PADDING_CAP, 1.0f, 8.0f);
  const GlintLodQuery good = make_query(0.5f, 0.0f, 0.0f, 0.5f, 64, 64, 100, 100);
  ASSERT_GT(lm::glint_lod(good, atlas), 0.0f);
  std::vector<std::pair<GlintLodQuery, GlintLodAtlas>> bad;
  for (int field = 0; field < 4; ++field) {
    GlintLodQuery q = good;
    (&q.dudx)[field] = nan;
    bad.emplace_back(q, atlas);
    (&q.dudx)[field] = inf;
    bad.emplace_back(q, atlas);
  }
  {
    GlintLodQuery q = good;
    q.off_x = kAtlas - 32;  // tile 64 wide: outside on the right
    bad.emplace_back(q, atlas);
    q = good;
    q.off_y = -1.0f;
    bad.emplace_back(q, atlas);
    q = good;
    q.tex_w = 0.0f;
    bad.emplace_back(q, atlas);
    q = good;
    q.tex_h = 0.0f;
    bad.emplace_back(q, atlas);
    GlintLodAtlas a = atlas;
    a.levels = 0.0f;
    bad.emplace_back(good, a);
    a.levels = nan;
    bad.emplace_back(good, a);
    a = atlas;
    a.atlas_w = nan;
    bad.emplace_back(good, a);
  }
  for (const auto& [q, a] : bad) {
    EXPECT_EQ(lm::glint_lod(q, a), 0.0f) << describe(q, a);
    EXPECT_EQ(ref::lod(q, a), 0.0) << describe(q, a);
  }
}

// No clamp(x, 0.0, 0.0) bug (docs/LOD.md, "The clamp bug"): a valid query with large derivatives returns
// levels - 1 on every path (isotropic, anisotropic, with bias, with a generous padding cap), also
// for derivatives so large that the float scale factors overflow.
TEST(LodMath, LargeDerivativesReachTopLevel) {
  for (int levels = 1; levels <= 13; ++levels) {
    // (The anisotropic padding cap is left out: a footprint this long fits no padding, so the cap
    // rightly gives 0; PaddingCapCoversAnisotropicMajorAxis tests it.)
    for (uint32_t flags : {0u, uint32_t(GLINT_LOD_ANISOTROPIC), uint32_t(GLINT_LOD_PADDING_CAP)}) {
      for (float bias : {-2.0f, 0.0f, 2.0f}) {
        for (float d : {1e3f, 1e6f, 1e12f, 1e20f, 1e30f}) {
          // Padding large enough that the cap never binds.
          const GlintLodAtlas a = make_atlas(kAtlas, kAtlas, float(levels), bias, flags, 16.0f, 1e38f);
          for (const GlintLodQuery& q : {make_query(d, 0, 0, d, 64, 32, 64, 64), make_query(d, d, -d, d, 4096, 4096),
                                         make_query(0, d * 1e4f, 0, 0, 1, 1, 4095, 4095)}) {
            EXPECT_EQ(lm::glint_lod(q, a), float(levels - 1)) << describe(q, a);
            EXPECT_EQ(ref::lod(q, a), double(levels - 1)) << describe(q, a);
          }
        }
      }
    }
  }
}

// No magic factor (such as 0.35) and no atlas scaling: one tile texel per pixel is level 0,
// 2^k texels per pixel level k, for any tile size and position; the bias default is 0.
TEST(LodMath, NoMagicFactorOneTexelPerPixelIsLevelZero) {
  const GlintLodAtlas atlas = make_atlas(kAtlas, kAtlas, kAtlasLevels);
  const GlintLodQuery q256 = make_query(1.0f / 256, 0.0f, 0.0f, 1.0f / 256, 256, 256, 1024, 2048);
  EXPECT_EQ(lm::glint_lod_unclamped(q256, atlas), 0.0f);
  EXPECT_EQ(lm::glint_lod(q256, atlas), 0.0f);
  EXPECT_EQ(ref::lod_unclamped(q256, atlas), 0.0);
  for (int k = 0; k <= 12; ++k) {
    for (float size : {1.0f, 16.0f, 256.0f, 1000.0f, 4096.0f}) {
      const float d = std::ldexp(1.0f, k) / size;
      const GlintLodQuery q = make_query(d, 0.0f, 0.0f, d, size, size, kAtlas - size, 0);
      EXPECT_FLOAT_EQ(lm::glint_lod_unclamped(q, atlas), float(k)) << size;
      EXPECT_FLOAT_EQ(lm::glint_lod(q, atlas), float(k)) << size;
      EXPECT_NEAR(ref::lod(q, atlas), k, 1e-6) << size;  // d is rounded to float
    }
  }
}

// The window the specification allows a sampler (isotropic): max(m_u, m_v) .. sqrt(2)(m_u + m_v)
// per direction. The exact length lies 0 .. 0.5 levels above the lower end and the window is at
// most 1.5 levels wide; both ends are reached.
TEST(LodMath, SpecificationWindowContainsExactLength) {
  std::mt19937 rng(7u);
  int interior = 0;
  for (int i = 0; i < 20000; ++i) {
    const GlintLodQuery q = random_query(rng);
    GlintLodAtlas a = random_atlas(rng);
    a.flags = 0u;
    const double lo = ref::spec_lod_lower(q, a), hi = ref::spec_lod_upper(q, a);
    const double exact = ref::lod(q, a);
    const float twin = lm::glint_lod(q, a);
    EXPECT_LE(lo, exact + 1e-12) << describe(q, a);
    EXPECT_LE(exact, hi + 1e-12) << describe(q, a);
    EXPECT_LE(exact - lo, 0.5 + 1e-12) << describe(q, a);
    EXPECT_LE(hi - exact, 1.0 + 1e-12) << describe(q, a);
    EXPECT_LE(hi - lo, 1.5 + 1e-12) << describe(q, a);
    EXPECT_GE(twin, lo - kTol) << describe(q, a);
    EXPECT_LE(twin, hi + kTol) << describe(q, a);
    if (lo > 0.0 && hi < a.levels - 1.0) ++interior;
  }
  EXPECT_GT(interior, 2000);
  const GlintLodAtlas a = make_atlas(kAtlas, kAtlas, kAtlasLevels);
  // Axis-aligned: exact == lower, upper = lower + 0.5.
  const GlintLodQuery axis = make_query(8.0f / 64, 0.0f, 0.0f, 8.0f / 64, 64, 64);
  EXPECT_DOUBLE_EQ(ref::spec_lod_lower(axis, a), 3.0);
  EXPECT_DOUBLE_EQ(ref::lod(axis, a), 3.0);
  EXPECT_DOUBLE_EQ(ref::spec_lod_upper(axis, a), 3.5);
  // Diagonal: exact = lower + 0.5, upper = lower + 1.5.
  const GlintLodQuery diag = make_query(8.0f / 64, 8.0f / 64, 0.0f, 0.0f, 64, 64);
  EXPECT_DOUBLE_EQ(ref::spec_lod_lower(diag, a), 3.0);
  EXPECT_DOUBLE_EQ(ref::lod(diag, a), 3.5);
  EXPECT_DOUBLE_EQ(ref::spec_lod_upper(diag, a), 4.5);
  EXPECT_DOUBLE_EQ(ref::spec_rho_lower(diag), 8.0);
  EXPECT_DOUBLE_EQ(ref::spec_rho_upper(diag), 16.0 * std::sqrt(2.0));
}

}  // namespace
