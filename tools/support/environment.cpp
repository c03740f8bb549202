#include "support/environment.h"

#include <cstdio>
#include <cstdlib>
#include <string>

namespace glint::tools {

namespace {

// GLINT_X=0 or 1; unset leaves `value` as it is.
void read_flag(const char* name, bool& value) {
  const char* v = std::getenv(name);
  if (!v || !*v) return;
  const std::string s(v);
  if (s != "0" && s != "1") {
    throw Error(ErrorCode::invalid_argument, std::string(name) + " = '" + s + "' is not a flag: accepted 0 or 1");
  }
  value = s == "1";
}

}  // namespace

ContextOptions context_options_from_environment(ContextOptions base) {
  if (const char* d = std::getenv("GLINT_DEVICE"); d && *d && base.device.empty()) base.device = d;
  read_flag("GLINT_VALIDATION", base.validation);
  read_flag("GLINT_GPU_AV", base.gpu_assisted_validation);
  if (base.gpu_assisted_validation) base.validation = true;
  if (const char* w = std::getenv("GLINT_WORKGROUP"); w && *w) {
    unsigned x = 0, y = 0;
    char tail = 0;
    if (std::sscanf(w, "%ux%u%c", &x, &y, &tail) != 2 || x == 0 || y == 0) {
      throw Error(ErrorCode::invalid_argument,
                  std::string("GLINT_WORKGROUP = '") + w + "' is malformed: accepted WxH with W, H >= 1 (e.g. 16x8)");
    }
    base.workgroup_2d = {x, y};
  }
  return base;
}

}  // namespace glint::tools
