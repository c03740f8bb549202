// libFuzzer target for the LIGHTS.json parser (tools/io/lights_json.cpp): any bytes must give a
// light list or glint::Error(invalid_argument), never a crash, a hang or an unbounded allocation;
// a parsed list must survive to_lights_json and parse again to the same floats.
#include <glint/glint.h>

#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <string_view>

#include "io/lights_json.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    const glint::io::LightsFile file = glint::io::parse_lights_json(text);
    if (file.lights.size() > glint::io::kMaxLights) std::abort();
    const glint::io::LightsFile again = glint::io::parse_lights_json(glint::io::to_lights_json(file));
    if (again.lights.size() != file.lights.size()) std::abort();
    if (std::memcmp(again.view_proj.data(), file.view_proj.data(), sizeof(float) * 16) != 0) std::abort();
    if (!file.lights.empty() &&
        std::memcmp(again.lights.data(), file.lights.data(), file.lights.size() * sizeof(file.lights[0])) != 0) {
      std::abort();
    }
  } catch (const glint::Error& e) {
    if (e.code() != glint::ErrorCode::invalid_argument) std::abort();
  }
  return 0;
}
