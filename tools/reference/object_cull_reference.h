// Float64 reference of the object cull (include/glint/object_cull.h, docs/OCCLUSION.md "Object
// culling"), written from the documented rules, independently of src/visibility/shaders/object_cull.comp:
// - state(): the cull's decision procedure in double with the fp32 rounding margins scaled by a
//   factor: 1 is what the GPU is designed to compute; the GPU's margins exceed its fp32 error by at
//   least 2x, so its effective factor lies in [0.5, 1.5], and since every margin only moves a
//   decision towards "visible", a state equal at factors 0.5 and 2 is the GPU's state;
// - brute force: margins 0, the exact projected rectangle (a sphere's tangent-line bounds, a box's
//   projected corners) read at full resolution, every pixel it touches: the truth the cull must
//   never fall below (an object visible here is visible on the GPU).
// CPU only: no Vulkan call is made here.
#pragma once

#include <cstdint>
#include <vector>

#include "glint/gpu/object_cull.h"
#include "reference/occlusion_reference.h"

namespace glint::reference {

/// The camera as the cull receives it (fp32 matrices, column-major) and the depth convention.
struct ObjectCamera {
  float view[16];
  float proj[16];
  bool reversed_z = false;
};

/// The reference's verdict on one object.
struct ObjectVerdict {
  uint32_t expected = GLINT_OBJECT_STATE_NONE;  // state at margin factor 1
  uint32_t brute = GLINT_OBJECT_STATE_NONE;     // brute-force state (exact, full resolution)
  bool ambiguous = false;                       // states at factors 0.5 and 2 differ
  bool invalid = false;                         // malformed bounds (visible)
};

/// The state of `object` at margin factor `margin` (0: exact), reading the Hi-Z pyramid
/// (`pyramid[k - 1]` is level k, `depth` level 0) or, when `full_res`, every pixel at level 0.
/// frustum_only: phase 1 (no occlusion test). Sets `invalid` for malformed bounds.
uint32_t object_state(const GlintCullObject& object, const ObjectCamera& camera, const DepthImage& depth,
                      const std::vector<DepthImage>& pyramid, double margin, bool full_res, bool frustum_only,
                      bool* invalid = nullptr);

/// expected, brute, ambiguous and invalid of one object.
ObjectVerdict judge_object(const GlintCullObject& object, const ObjectCamera& camera, const DepthImage& depth,
                           const std::vector<DepthImage>& pyramid);

/// A Vulkan perspective projection (column-major, fp32): vertical field of view fov_y (radians),
/// aspect, near, far (far <= 0: infinite), standard or reversed Z, y flipped (P11 < 0) if flip_y.
void perspective(double fov_y, double aspect, double near_z, double far_z, bool reversed_z, bool flip_y, float out[16]);

}  // namespace glint::reference
