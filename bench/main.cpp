// glint_bench: Google Benchmark main; the device is chosen by GLINT_DEVICE (index or name).
//
// --kernel_stats[=FILE]: also capture the driver's statistics of every compute pipeline the run
// makes (ContextOptions::kernel_statistics: VK_KHR_pipeline_executable_properties where the device
// has it) and write them, after the benchmarks, as JSON to FILE (default: stdout after the
// results), one record per pipeline executable: kernel, variant (workgroup | push bytes |
// specialization | descriptor types), executable, subgroup size and the driver's statistics
// (register count, shared memory, spills, instruction count, ...). With --benchmark_filter only
// the kernels of the selected benchmarks are made. Example:
//   glint_bench --benchmark_filter=ObjectCull --kernel_stats=kernel_stats.json
#include <benchmark/benchmark.h>

#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "bench_support.h"

namespace {

std::string json_string(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (static_cast<unsigned char>(c) < 0x20) {
      char buf[8];
      std::snprintf(buf, sizeof(buf), "\\u%04x", static_cast<unsigned>(static_cast<unsigned char>(c)));
      out += buf;
    } else {
      out += c;
    }
  }
  return out + "\"";
}

// Writes the statistics as JSON; returns false when the file cannot be written.
bool write_kernel_stats(const std::string& path) {
  const glint::Context& ctx = glint::bench::context();
  std::string j = "{\n  \"device\": " + json_string(ctx.info().name) +
                  ",\n  \"enabled\": " + (ctx.kernel_statistics_enabled() ? "true" : "false") + ",\n  \"pipelines\": [";
  const auto all = ctx.kernel_statistics();
  for (size_t i = 0; i < all.size(); ++i) {
    const auto& k = all[i];
    j += std::string(i ? "," : "") + "\n    {\"kernel\": " + json_string(k.kernel) +
         ", \"variant\": " + json_string(k.variant) + ", \"executable\": " + json_string(k.executable) +
         ", \"subgroup_size\": " + std::to_string(k.subgroup_size) + ", \"statistics\": {";
    for (size_t s = 0; s < k.statistics.size(); ++s) {
      j += std::string(s ? ", " : "") + json_string(k.statistics[s].name) + ": " + json_string(k.statistics[s].value);
    }
    j += "}}";
  }
  j += "\n  ]\n}\n";
  if (path.empty()) {
    std::fputs(j.c_str(), stdout);
    return true;
  }
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) return false;
  const bool ok = std::fwrite(j.data(), 1, j.size(), f) == j.size();
  return std::fclose(f) == 0 && ok;
}

}  // namespace

int main(int argc, char** argv) {
  bool stats = false;
  std::string stats_path;
  std::vector<char*> args;
  for (int i = 0; i < argc; ++i) {
    if (i > 0 && std::strcmp(argv[i], "--kernel_stats") == 0) {
      stats = true;
    } else if (i > 0 && std::strncmp(argv[i], "--kernel_stats=", 15) == 0) {
      stats = true;
      stats_path = argv[i] + 15;
    } else {
      args.push_back(argv[i]);
    }
  }
  int n = static_cast<int>(args.size());
  args.push_back(nullptr);
  glint::bench::set_kernel_statistics(stats);
  benchmark::Initialize(&n, args.data());
  if (benchmark::ReportUnrecognizedArguments(n, args.data())) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  if (stats) {
    if (!glint::bench::context().kernel_statistics_enabled()) {
      std::fprintf(stderr, "glint_bench: device %s lacks VK_KHR_pipeline_executable_properties: no kernel statistics\n",
                   glint::bench::context().info().name.c_str());
    }
    if (!write_kernel_stats(stats_path)) {
      std::fprintf(stderr, "glint_bench: cannot write %s\n", stats_path.c_str());
      return 1;
    }
  }
  return 0;
}
