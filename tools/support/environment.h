// The GLINT_* environment variables of the tools around the library (the glint command, the tests,
// the benchmarks). The library itself reads no environment: these map to ContextOptions.
//   GLINT_DEVICE=D        ContextOptions::device (an index from `glint devices` or part of a name)
//   GLINT_VALIDATION=1    ContextOptions::validation (0 or unset: off)
//   GLINT_GPU_AV=1        ContextOptions::gpu_assisted_validation (with validation)
//   GLINT_WORKGROUP=WxH   ContextOptions::workgroup_2d (benchmark tuning)
#pragma once

#include <glint/glint.h>

namespace glint::tools {

/// `base` with every GLINT_* variable that is set applied on top. Throws Error(invalid_argument)
/// naming the variable for a malformed value (GLINT_WORKGROUP not of the form WxH, a flag other
/// than 0 or 1).
ContextOptions context_options_from_environment(ContextOptions base = {});

}  // namespace glint::tools
