// Float64 reference LOD: see lod_reference.h and docs/LOD.md.
#include "reference/lod_reference.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace glint::reference {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Texel-space partial derivatives (spec: m_ux = |du/dx| with u = s * width, and so on).
struct Scale {
  double m_ux, m_vx, m_uy, m_vy;
};

Scale scale_factors(const GlintLodQuery& q) {
  const double w = q.tex_w, h = q.tex_h;
  return {std::fabs(double(q.dudx)) * w, std::fabs(double(q.dvdx)) * h, std::fabs(double(q.dudy)) * w,
          std::fabs(double(q.dvdy)) * h};
}

double top_level(const GlintLodAtlas& a) { return double(a.levels) - 1.0; }

double clamp_level(double lambda, const GlintLodAtlas& a) {
  // std::clamp keeps -inf / +inf inside the range; lambda is never NaN here.
  return std::clamp(lambda, 0.0, top_level(a));
}

}  // namespace

double lod_rho_x(const GlintLodQuery& q) {
  const Scale s = scale_factors(q);
  return std::hypot(s.m_ux, s.m_vx);
}

double lod_rho_y(const GlintLodQuery& q) {
  const Scale s = scale_factors(q);
  return std::hypot(s.m_uy, s.m_vy);
}

bool lod_valid(const GlintLodQuery& q, const GlintLodAtlas& a) {
  const double fields[] = {q.dudx,  q.dvdx,  q.dudy,    q.dvdy,    q.tex_w,  q.tex_h,
                           q.off_x, q.off_y, a.atlas_w, a.atlas_h, a.levels, a.bias};
  for (double f : fields) {
    if (!std::isfinite(f)) return false;
  }
  if ((a.flags & GLINT_LOD_ANISOTROPIC) != 0u && !(double(a.max_aniso) >= 1.0)) return false;  // NaN too
  if ((a.flags & GLINT_LOD_PADDING_CAP) != 0u && std::isnan(a.padding)) return false;
  if (!(q.tex_w >= 1.0f && q.tex_h >= 1.0f && a.levels >= 1.0f)) return false;
  if (q.off_x < 0.0f || q.off_y < 0.0f) return false;
  // Exact in double: a tile of (off, size) occupies [off, off + size).
  return double(q.off_x) + double(q.tex_w) <= double(a.atlas_w) &&
         double(q.off_y) + double(q.tex_h) <= double(a.atlas_h);
}

double lod_unclamped(const GlintLodQuery& q, const GlintLodAtlas& a) {
  if (!lod_valid(q, a)) return kNaN;
  const double rx = lod_rho_x(q), ry = lod_rho_y(q);
  const double rho_max = std::max(rx, ry), rho_min = std::min(rx, ry);
  double eta = 1.0;
  if ((a.flags & GLINT_LOD_ANISOTROPIC) != 0u) {
    const double max_aniso = a.max_aniso;
    if (rho_max == 0.0) {
      eta = 1.0;  // both zero
    } else if (rho_min == 0.0) {
      eta = max_aniso;
    } else {
      eta = std::min(rho_max / rho_min, max_aniso);
    }
  }
  if (rho_max == 0.0) return -kInf;  // infinite magnification, whatever the bias
  return std::log2(rho_max / eta) + double(a.bias);
}

double lod_padding_cap(const GlintLodQuery& q, const GlintLodAtlas& a) {
  const double padding = a.padding;
  if (std::isinf(padding) && padding > 0.0) return kInf;
  const double reach = (a.flags & GLINT_LOD_ANISOTROPIC) != 0u ? 0.5 * std::max(lod_rho_x(q), lod_rho_y(q)) : 0.0;
  // Largest integer L >= 0 with 2^(L+1) + reach <= padding; 0 when none.
  int level = 0;
  while (level < 2000 && std::ldexp(1.0, level + 2) + reach <= padding) ++level;
  return double(level);
}

double lod(const GlintLodQuery& q, const GlintLodAtlas& a) {
  if (!lod_valid(q, a)) return 0.0;
  double lambda = lod_unclamped(q, a);
  if ((a.flags & GLINT_LOD_PADDING_CAP) != 0u) lambda = std::min(lambda, lod_padding_cap(q, a));
  return clamp_level(lambda, a);
}

double spec_rho_lower(const GlintLodQuery& q) {
  const Scale s = scale_factors(q);
  return std::max(std::max(s.m_ux, s.m_vx), std::max(s.m_uy, s.m_vy));
}

double spec_rho_upper(const GlintLodQuery& q) {
  const Scale s = scale_factors(q);
  return std::max(std::sqrt(2.0) * (s.m_ux + s.m_vx), std::sqrt(2.0) * (s.m_uy + s.m_vy));
}

double spec_lod_lower(const GlintLodQuery& q, const GlintLodAtlas& atlas) {
  GlintLodAtlas a = atlas;
  a.flags = 0u;  // isotropic, no padding cap
  if (!lod_valid(q, a)) return 0.0;
  const double rho = spec_rho_lower(q);
  return rho > 0.0 ? clamp_level(std::log2(rho) + double(a.bias), a) : 0.0;
}

double spec_lod_upper(const GlintLodQuery& q, const GlintLodAtlas& atlas) {
  GlintLodAtlas a = atlas;
  a.flags = 0u;  // isotropic, no padding cap
  if (!lod_valid(q, a)) return 0.0;
  const double rho = spec_rho_upper(q);
  return rho > 0.0 ? clamp_level(std::log2(rho) + double(a.bias), a) : 0.0;
}

}  // namespace glint::reference
