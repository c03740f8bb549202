// Float64 CPU references of the lens-flare visibility stage (docs/OCCLUSION.md), written
// from the documented rules, independently of src/visibility/shaders/hiz_build.comp and
// src/visibility/shaders/light_cull.comp:
// - the Hi-Z pyramid, each texel computed directly as the farthest of the source pixels it covers
//   ([c * 2^k, (c + 1) * 2^k), the last texel of a row or column up to the edge), not by the
//   kernel's level-by-level fold;
// - the exact expected result of the grid test (projection in double, the same multi-jittered
//   sample footprints, level and clamp-to-edge windows), with a flag for lights where a decision
//   lies within rounding of a boundary (fp32 on the GPU may go either way there);
// - the brute-force visible fraction: every full-resolution pixel under the footprint, weighted
//   by its overlap area;
// - the error bound's numerator: samples whose window and cell together hold both visible and
//   occluded pixels.
// CPU only: no Vulkan call is made here.
#pragma once

#include <glint/gpu/flare_types.h>

#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

namespace glint::reference {

/// A depth image: width * height floats, row-major, top row first.
struct DepthImage {
  uint32_t width = 0, height = 0;
  std::vector<float> depth;
  float at(uint32_t x, uint32_t y) const { return depth[size_t(y) * width + x]; }
};

/// Hi-Z levels 1..levels (index 0 of the result is level 1); level k is max(1, size >> k) on a
/// side. Farthest = max for standard Z, min for reversed Z. Values are source values (exact).
std::vector<DepthImage> hiz_pyramid(const DepthImage& depth, bool reversed_z, uint32_t levels);

/// What the cull needs besides the light and the depth.
struct CullSettings {
  double view_proj[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};  // column-major
  uint32_t grid = 4;
  double margin_ndc = 1.2;
  double depth_bias = 0.0;
  bool reversed_z = false;
  uint32_t levels = 0;        // Hi-Z levels available above level 0
  bool regular_grid = false;  // OcclusionPattern::regular: each cell reads the cell itself
};

/// Footprint [first, second) along one axis of the sample of cell (i, j) (column i, row j; call
/// with (j, i) for the y axis), in units of cell / (2n) from the light's left (top) edge.
/// Multi-jittered (Chiu, Shirley & Wang 1994, canonical): the sample sits at i + (j + 0.5) / n
/// cells, its footprint is one cell wide around it, reaching (n - 1) / (2n) cell further out on the
/// light's border. regular_grid: the cell [i, i + 1).
std::pair<int, int> sample_footprint(uint32_t i, uint32_t j, uint32_t n, bool regular_grid);

/// The reference's verdict on one light.
struct LightVisibility {
  uint32_t culled = GLINT_FLARE_DISABLED;  // GLINT_FLARE_VISIBLE / _FRUSTUM / _OCCLUDED / _DISABLED
  double grid_fraction = 0.0;              // expected result of the grid test (visible samples / N^2)
  double brute_force = 0.0;                // area-weighted visible fraction of the footprint at full resolution
  uint32_t mixed_cells = 0;                // samples whose window + cell hold visible and occluded pixels
                                           // (or whose window is not read): |grid - brute| <= this / N^2
  uint32_t level = 0;                      // Hi-Z level the cells were read at
  bool ambiguous = false;                  // a decision lies within fp32 rounding of a boundary
  double center_x = 0, center_y = 0, ndc_z = 0;
};

/// Evaluates one light. `pyramid` is hiz_pyramid(depth, settings.reversed_z, settings.levels).
/// enabled == 0 or a non-finite float field (position, intensity, colour, size_px): DISABLED.
/// `brute_force` and `mixed_cells` are computed only for lights that pass the frustum test.
LightVisibility cull_light(const GlintFlareLight& light, const CullSettings& settings, const DepthImage& depth,
                           const std::vector<DepthImage>& pyramid);

/// A perspective camera at the origin looking down -z (right-handed), Vulkan clip space (depth 0 at
/// the near plane, 1 at the far plane; reversed: 1 near, 0 far), for building test scenes.
struct Camera {
  double fov_y = 1.0;  // radians
  double aspect = 1.0;
  double near_z = 0.1;
  double far_z = 100.0;
  bool reversed_z = false;
};
/// The column-major view-projection matrix of `camera`.
void camera_view_proj(const Camera& camera, double out[16]);
/// The world position that projects to (ndc_x, ndc_y, ndc_z); ndc_z < 0 (standard) gives a point
/// behind the camera.
void camera_unproject(const Camera& camera, double ndc_x, double ndc_y, double ndc_z, float out[3]);

/// A random scene: a depth buffer of boxes (sloped, at random depths, some crossing the screen
/// edges) over the far plane, and lights in front of and behind them, at the screen edges, partly
/// and wholly off screen (inside and outside the margin), behind the camera, beyond the far plane
/// and disabled. Sizes are uniform in [0.5, max_size_px].
struct Scene {
  DepthImage depth;
  std::vector<GlintFlareLight> lights;
  Camera camera;
  double view_proj[16];
};
Scene random_scene(uint32_t width, uint32_t height, uint32_t light_count, uint32_t stream, bool reversed_z,
                   double max_size_px);

/// True if a stored depth `d` lets a light at depth `z` be seen (not nearer than z - bias).
bool depth_visible(double d, double z, const CullSettings& settings);

}  // namespace glint::reference
