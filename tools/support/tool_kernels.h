// The SPIR-V of the tools' kernels (the demo scene's starfield), embedded at build time in
// glint_tools_kernels by the same function as the library's (glint_add_kernels in
// cmake/GlintKernels.cmake) but outside libglint: pass the binary in PipelineDesc::binary.
#pragma once

#include "core/kernel_table.h"

namespace glint::tools {

/// The tools' embedded kernel with this id, or null.
const detail::KernelBinary* find_kernel(const char* id);

}  // namespace glint::tools
