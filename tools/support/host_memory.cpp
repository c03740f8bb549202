#include "support/host_memory.h"

#include <glint/glint.h>
#include <unistd.h>

#include <cstdio>
#include <cstring>
#include <fstream>
#include <string>

namespace glint::tools {

uint64_t available_host_memory() {
  std::ifstream meminfo("/proc/meminfo");
  std::string key;
  uint64_t kib = 0;
  std::string unit;
  while (meminfo >> key >> kib >> unit) {
    if (key == "MemAvailable:") return kib * 1024;
  }
  const long pages = sysconf(_SC_AVPHYS_PAGES), page = sysconf(_SC_PAGESIZE);
  return pages > 0 && page > 0 ? uint64_t(pages) * uint64_t(page) : 0;
}

void check_host_memory(const std::string& what, uint64_t bytes) {
  const uint64_t available = available_host_memory();
  if (available == 0 || bytes <= available) return;
  char text[160];
  std::snprintf(text, sizeof text, " needs about %llu MiB of host memory; %llu MiB are available",
                static_cast<unsigned long long>(bytes >> 20), static_cast<unsigned long long>(available >> 20));
  throw Error(ErrorCode::unsupported_size, what + text);
}

}  // namespace glint::tools
