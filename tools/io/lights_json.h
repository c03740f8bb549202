// LIGHTS.json, the light list of `glint flare`: a view-projection matrix and a
// list of lights, parsed strictly into the GPU's GlintFlareLight layout (include/glint/
// gpu/flare_types.h). The parser is a pure function of the text (no file, no Vulkan), so that a fuzz
// target can call it directly.
//
// Format (every key below; no other key is accepted, so a typo is an error, not a silent default):
//   {"view_proj": [16 numbers, column-major (GLM)],                     required
//    "lights": [                                                        required, 0 to kMaxLights
//      {"position": [x, y, z],            world space, finite            required
//       "color": [r, g, b],               linear RGB, each 0 to 65504    default [1, 1, 1]
//       "intensity": f,                   0 to 65504                     default 1
//       "size": px,                       flare size in pixels, > 0 and at most kMaxSizePx
//                                                                        default 100 (kDefaultSizePx)
//       "element": "glow",                glow | streak | halo | starburst | ghost (any case)
//                                                                        default "glow"
//       "enabled": true}                  false: counted as disabled, never drawn
//                                                                        default true
//    ]}
// Numbers must be finite and within float range (JSON has no NaN or Inf, but 1e39 overflows a
// float and is rejected, as is 1e400, which overflows a double). Duplicate keys are rejected.
#pragma once

#include <glint/gpu/flare_types.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace glint::io {

/// The most lights one LIGHTS.json may hold. The cull takes up to 4,194,240 per dispatch; one
/// million keeps the light and instance buffers at 48 MB each and the file (about 150 bytes per
/// light) around 150 MB, which the reader still holds in memory at once.
inline constexpr size_t kMaxLights = 1000000;
/// The largest accepted "size" in pixels: a flare's sprites span up to ~10x this (streak length x
/// anamorphic ratio), so anything larger covers a 16384-pixel image many times over.
inline constexpr double kMaxSizePx = 4096.0;
/// Upper bound of colour components and intensity: the largest finite fp16 value (the HDR image).
inline constexpr double kMaxColor = 65504.0;
/// Default "size" when a light has none: 100 px, a mid-sized flare in a 1080p frame.
inline constexpr float kDefaultSizePx = 100.0f;
/// Largest LIGHTS.json file that load_lights_json() reads (kMaxLights at ~250 bytes each).
inline constexpr uint64_t kMaxLightsFileBytes = uint64_t(256) << 20;

/// A parsed LIGHTS.json.
struct LightsFile {
  std::array<float, 16> view_proj{};    //!< column-major (GLM), as in the file
  std::vector<GlintFlareLight> lights;  //!< in file order; reserved fields 0, enabled 0 or 1
};

/// Parses the text of a LIGHTS.json.
///
/// Validates everything described at the top of this file and returns the lights in the GPU's
/// layout. Hostile input (deep nesting, huge arrays or strings, garbage) is rejected at the first
/// value that breaks the schema, so memory stays proportional to the accepted lights.
/// text: the whole file; need not be NUL-terminated.
/// Throws Error(invalid_argument) with a one-line message naming the JSON path (e.g.
/// "lights[3].size") and the accepted type or range; throws nothing else.
LightsFile parse_lights_json(std::string_view text);

/// Reads `path` (at most kMaxLightsFileBytes) and parses it. Errors name the path:
/// Error(io_failure) when the file cannot be read, Error(invalid_argument) for its content.
LightsFile load_lights_json(const std::string& path);

/// The JSON text of `file` in the format above (every key written, floats in shortest round-trip
/// form, so parse_lights_json(to_lights_json(f)) gives back identical floats).
std::string to_lights_json(const LightsFile& file);

/// The name of a GLINT_FLARE_ELEMENT_* value ("glow", ...), "glow" for anything out of range.
const char* flare_element_name(uint32_t element);

}  // namespace glint::io
