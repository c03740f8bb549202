// Host memory the tools check before they start work that needs much of it (the glint command's
// demo at its largest sizes), so that a size the machine cannot hold is refused up front with a
// message naming the bytes, instead of the process being killed by the kernel minutes later.
#pragma once

#include <cstdint>
#include <string>

namespace glint::tools {

/// Bytes of host memory available to a new allocation: MemAvailable from /proc/meminfo where the
/// system has it, else the free physical pages (sysconf). 0 when neither can be read.
uint64_t available_host_memory();

/// Throws Error(unsupported_size) "<what> needs about N MiB of host memory; M MiB are available"
/// when `bytes` exceeds available_host_memory() (and that is known).
void check_host_memory(const std::string& what, uint64_t bytes);

}  // namespace glint::tools
