// Float64 CPU reference of glint's atlas-aware texture LOD (docs/LOD.md). Written from
// the Vulkan specification's "LOD Operation", independently of include/glint/gpu/lod_impl.h: same
// inputs (GlintLodQuery / GlintLodAtlas from include/glint/gpu/lod.h), same contract, but double
// precision throughout, std::hypot for the exact gradient length and an integer search for the
// padding cap. CPU only: no Vulkan call is made here.
#pragma once

#include <glint/gpu/lod.h>

namespace glint::reference {

/// Texel-space scale factor along screen x: the exact length of (|du/dx| * tex_w, |dv/dx| * tex_h).
double lod_rho_x(const GlintLodQuery& q);
/// The same along screen y: the exact length of (|du/dy| * tex_w, |dv/dy| * tex_h).
double lod_rho_y(const GlintLodQuery& q);

/// True when the query and atlas are usable: every field that is read is finite (padding only
/// with GLINT_LOD_PADDING_CAP, where +inf is allowed; max_aniso only with GLINT_LOD_ANISOTROPIC,
/// where it must be >= 1, +inf allowed), tex_w, tex_h >= 1, levels >= 1, and the tile lies
/// inside the atlas (0 <= off, off + size <= atlas size).
bool lod_valid(const GlintLodQuery& q, const GlintLodAtlas& a);

/// lambda_base + bias before any clamp or cap (spec: isotropic rho = max(rho_x, rho_y);
/// anisotropic eta = min(rho_max / rho_min, max_aniso), 1 when both rho are 0, max_aniso when only
/// rho_min is 0; lambda_base = log2(rho_max / eta)). -infinity for a zero footprint. Only meaningful
/// for valid input (NaN is returned otherwise).
double lod_unclamped(const GlintLodQuery& q, const GlintLodAtlas& a);

/// The padding cap: the largest integer L >= 0 with 2^(L+1) + reach <= padding, where reach is
/// rho_max / 2 with GLINT_LOD_ANISOTROPIC and 0 otherwise; 0 when not even L = 0 fits; +inf for
/// an infinite padding. Ignores GLINT_LOD_PADDING_CAP (the caller decides whether to apply it).
double lod_padding_cap(const GlintLodQuery& q, const GlintLodAtlas& a);

/// The level: lod_unclamped, then min with the padding cap when GLINT_LOD_PADDING_CAP is set, then
/// clamped to [0, levels - 1]. Invalid input (see lod_valid) gives 0. Never NaN.
double lod(const GlintLodQuery& q, const GlintLodAtlas& a);

// The specification lets a sampler approximate rho_x by any f_x (continuous, monotonic in m_ux
// and m_vx) with max(m_ux, m_vx) <= f_x <= sqrt(2) * (m_ux + m_vx), and rho_y likewise. These
// give the resulting window for the isotropic rho = max(rho_x, rho_y) of a conformant sampler.

/// max over x and y of max(|m_u|, |m_v|) (texel units).
double spec_rho_lower(const GlintLodQuery& q);
/// max over x and y of sqrt(2) * (|m_u| + |m_v|) (texel units).
double spec_rho_upper(const GlintLodQuery& q);

/// The isotropic LOD window a conformant sampler (anisotropy off, no padding cap) may return:
/// clamp(log2(spec_rho_lower) + bias, 0, levels - 1) and the same with spec_rho_upper. The
/// anisotropic flag and the padding cap are ignored; invalid input gives 0 for both.
/// upper - lower <= 1.5 levels; the exact length lies 0 .. 0.5 above lower and 0 .. 1 below upper.
double spec_lod_lower(const GlintLodQuery& q, const GlintLodAtlas& a);
double spec_lod_upper(const GlintLodQuery& q, const GlintLodAtlas& a);

}  // namespace glint::reference
