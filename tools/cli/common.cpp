#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "cli/commands.h"
#include "core/resources.h"
#include "io/exr_io.h"
#include "support/environment.h"
#include "support/transfer.h"

namespace glint::cli {

const char* device_type_name(VkPhysicalDeviceType type) {
  switch (type) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU:
      return "discrete GPU";
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU:
      return "integrated GPU";
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU:
      return "virtual GPU";
    case VK_PHYSICAL_DEVICE_TYPE_CPU:
      return "CPU";
    default:
      return "other";
  }
}

VkExtent2D parse_size(const std::string& option, const std::string& text) {
  const auto bad = [&] {
    return Error(ErrorCode::invalid_argument, option + ": '" + text + "' is not WIDTHxHEIGHT with each from 1 to " +
                                                  std::to_string(io::kMaxImageDimension) + " (e.g. 1920x1080)");
  };
  const size_t x = text.find_first_of("xX");
  if (x == std::string::npos || x == 0 || x + 1 >= text.size()) throw bad();
  uint32_t w = 0, h = 0;
  const char* begin = text.data();
  const char* end = text.data() + text.size();
  const auto rw = std::from_chars(begin, begin + x, w);
  const auto rh = std::from_chars(begin + x + 1, end, h);
  if (rw.ec != std::errc() || rw.ptr != begin + x || rh.ec != std::errc() || rh.ptr != end) throw bad();
  if (w == 0 || h == 0 || w > io::kMaxImageDimension || h > io::kMaxImageDimension) throw bad();
  return {w, h};
}

void check_exposure(float exposure) {
  if (!std::isfinite(exposure) || !(exposure > 0.0f)) {
    char text[128];
    std::snprintf(text, sizeof text, "--exposure = %g is out of range: accepted finite and > 0", double(exposure));
    throw Error(ErrorCode::invalid_argument, text);
  }
}

void check_output_path(const std::string& path) {
  namespace fs = std::filesystem;
  const fs::path p(path);
  const fs::path dir = p.has_parent_path() ? p.parent_path() : fs::path(".");
  std::error_code ec;
  if (!fs::is_directory(dir, ec))
    throw Error(ErrorCode::io_failure, path + ": directory " + dir.string() + " does not exist");
  if (fs::is_directory(p, ec)) throw Error(ErrorCode::io_failure, path + ": is a directory");
}

void check_distinct_outputs(const std::vector<std::string>& options, const std::vector<std::string>& paths) {
  namespace fs = std::filesystem;
  std::vector<fs::path> resolved;
  for (const std::string& p : paths) {
    std::error_code ec;
    fs::path r = fs::weakly_canonical(fs::absolute(p, ec), ec);
    resolved.push_back(ec ? fs::path(p) : r);
  }
  for (size_t i = 0; i < paths.size(); ++i) {
    for (size_t j = 0; j < i; ++j) {
      if (resolved[i] == resolved[j]) {
        throw Error(ErrorCode::invalid_argument, options[j] + " and " + options[i] + " are the same file (" + paths[i] +
                                                     "); each output needs its own path");
      }
    }
  }
}

FlareConfig flare_preset_from_name(const std::string& name) {
  std::string n = name;
  std::transform(n.begin(), n.end(), n.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (n == "retro_subtle") return FlareConfig::preset(FlarePreset::retro_subtle);
  if (n == "retro_intense") return FlareConfig::preset(FlarePreset::retro_intense);
  if (n == "cinematic") return FlareConfig::preset(FlarePreset::cinematic);
  if (n == "disabled") return FlareConfig::preset(FlarePreset::disabled);
  if (n == "default") return FlareConfig{};
  throw Error(ErrorCode::invalid_argument, "--preset: '" + name +
                                               "' is not a preset; accepted retro_subtle, retro_intense, cinematic, "
                                               "disabled or default (any case)");
}

void add_device_option(CLI::App& sub, std::string& device) {
  sub.add_option("--device", device,
                 "Vulkan device: an index from 'glint devices' or part of its name (default: GLINT_DEVICE, "
                 "else the first discrete GPU, integrated GPU, then CPU)");
}

void print_stages(const Profiler& profiler) {
  const auto stages = profiler.results();
  if (stages.empty()) {
    std::printf("GPU time: not available (the device has no timestamp queries)\n");
    return;
  }
  std::printf("GPU time per stage:\n");
  for (const auto& s : stages) std::printf("  %-28s %9.3f ms\n", s.label.c_str(), s.ms);
  std::printf("  %-28s %9.3f ms\n", "total", profiler.total_ms());
}

Context make_context(const std::string& device) {
  ContextOptions options;
  options.device = device;  // --device wins over GLINT_DEVICE
  return Context::create(tools::context_options_from_environment(options));
}

void print_device(const Context& context, const std::string& input_path, const CpuImage& input) {
  std::printf("device: %s (%s)\n", context.info().name.c_str(), device_type_name(context.info().type));
  std::printf("input: %s, %ux%u\n", input_path.c_str(), input.width, input.height);
}

void check_device_images(const Context& context, VkExtent2D extent, VkFormat output_format) {
  // Made and freed at once: each allocation checks the device's budget (and the image its
  // maxResourceSize) and throws Error(unsupported_size) naming the bytes needed and available.
  detail::OwnedImage source(context, extent, VK_FORMAT_R32G32B32A32_SFLOAT, detail::kToolImageUsage);
  detail::OwnedImage result(context, extent, output_format, detail::kToolImageUsage);
}

void run_on_input(const Context& context, const CpuImage& input, Profiler& profiler,
                  const std::function<void(VkCommandBuffer, Image& source, Profiler*)>& effect) {
  detail::OwnedImage source(context, {input.width, input.height}, VK_FORMAT_R32G32B32A32_SFLOAT,
                            detail::kToolImageUsage);
  detail::upload(context, source.image(), input);
  context.run_once([&](VkCommandBuffer cmd) {
    profiler.reset(cmd);
    profiler.mark(cmd, "start");
    effect(cmd, source.image(), &profiler);
  });
}

CpuImage run_image_effect(const Context& context, const CpuImage& input, Profiler& profiler,
                          const std::function<void(VkCommandBuffer, Image& source, Image& result, Profiler*)>& effect,
                          VkFormat output_format) {
  detail::OwnedImage result(context, {input.width, input.height}, output_format, detail::kToolImageUsage);
  run_on_input(context, input, profiler,
               [&](VkCommandBuffer cmd, Image& source, Profiler* p) { effect(cmd, source, result.image(), p); });
  return detail::download(context, result.image());
}

void write_result_exr(const std::string& path, const CpuImage& image, bool fp32) {
  if (fp32)
    io::write_exr_float(path, image);
  else
    io::write_exr_half(path, image);
}

// The depth channel: Z, else the first channel; every value finite and in [0, 1].
io::ExrChannel read_depth_exr(const std::string& path) {
  io::ExrChannel d = io::read_exr_channel(path, "Z");
  for (size_t i = 0; i < d.values.size(); ++i) {
    const float v = d.values[i];
    if (!(v >= 0.0f && v <= 1.0f)) {
      char text[160];
      std::snprintf(text, sizeof text, ": channel %s at pixel (%zu, %zu) is %g; depth must be in [0, 1]",
                    d.name.c_str(), i % d.width, i / d.width, double(v));
      throw Error(ErrorCode::invalid_argument, path + text);
    }
  }
  return d;
}

}  // namespace glint::cli
