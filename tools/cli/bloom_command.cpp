// glint bloom IN.exr OUT.exr: bloom of an EXR file on a standalone context, written as RGBA half
// EXR (and optionally a tonemapped PNG). Ranges are checked by BloomConfig::validate(), not here,
// so the CLI and the library can never disagree about them.
#include <glint/bloom.h>

#include <cstdio>
#include <memory>

#include "cli/commands.h"
#include "core/check.h"
#include "core/resources.h"
#include "io/atomic_outputs.h"
#include "io/exr_io.h"
#include "io/png_io.h"
#include "support/host_memory.h"
#include "support/transfer.h"

namespace glint::cli {
namespace {

struct BloomOptions {
  std::string input;
  std::string output;
  std::string png;
  std::string device;
  std::string filter = "cod13";
  std::string guard = "karis_smooth";
  bool fp32 = false;
  float exposure = 1.0f;
  BloomConfig config;
};

BloomFilter filter_from_name(const std::string& name) {
  if (name == "dual") return BloomFilter::dual;
  if (name == "gauss9") return BloomFilter::gauss9;
  return BloomFilter::cod13;  // IsMember() has already rejected anything else
}

FireflyGuard guard_from_name(const std::string& name) {
  if (name == "off") return FireflyGuard::off;
  if (name == "karis") return FireflyGuard::karis;
  return FireflyGuard::karis_smooth;  // IsMember() has already rejected anything else
}

void run_bloom(BloomOptions& o) {
  o.config.filter = filter_from_name(o.filter);
  o.config.firefly_guard = guard_from_name(o.guard);
  o.config.precision = o.fp32 ? Precision::fp32 : Precision::fp16;
  o.config.validate();  // bad flags fail before any file or device is touched
  check_exposure(o.exposure);
  check_output_path(o.output);
  if (!o.png.empty()) {
    check_output_path(o.png);
    check_distinct_outputs({"OUT", "--png"}, {o.output, o.png});
  }

  // Everything the run holds is checked from the file's header, before its pixels are decoded
  // (seconds rather than minutes at 16384x16384): host memory for the input and the result as
  // RGBA float, then the device memory of the pyramid, the float input image and the result.
  const io::ExrExtent size = io::read_exr_extent(o.input);
  const VkExtent2D extent{size.width, size.height};
  const VkFormat output_format = o.fp32 ? VK_FORMAT_R32G32B32A32_SFLOAT : VK_FORMAT_R16G16B16A16_SFLOAT;
  tools::check_host_memory(detail::concat("glint bloom of a ", extent.width, "x", extent.height, " image"),
                           2 * uint64_t(extent.width) * extent.height * 4 * sizeof(float));
  const Context context = make_context(o.device);
  Bloom bloom(context, o.config);
  bloom.prepare(extent);  // throws unsupported_size before any image is made for a too-large input
  check_device_images(context, extent, output_format);

  const CpuImage input = io::read_exr(o.input);
  Profiler profiler(context);
  const CpuImage output = run_image_effect(
      context, input, profiler,
      [&](VkCommandBuffer cmd, Image& in, Image& out, Profiler* p) { bloom.record(cmd, in, out, p); }, output_format);
  print_device(context, o.input, input);
  std::printf("bloom: filter %s, %s intermediates, %u level%s", bloom_filter_name(o.config.filter),
              o.fp32 ? "fp32" : "fp16", bloom.levels(), bloom.levels() == 1 ? "" : "s");
  if (bloom.clamped()) {
    std::printf(" (clamped: --iterations %u does not fit %ux%u)\n", o.config.iterations, input.width, input.height);
  } else {
    std::printf(" (not clamped)\n");
  }
  print_stages(profiler);

  io::AtomicOutputs files;  // OUT and --png are replaced together, only once both are written
  files.write(o.output, [&](const std::string& tmp) { write_result_exr(tmp, output, o.fp32); });
  if (!o.png.empty()) {
    files.write(o.png, [&](const std::string& tmp) { io::write_png_tonemapped(tmp, output, o.exposure); });
  }
  files.commit();
  for (const std::string& f : files.targets()) std::printf("wrote %s\n", f.c_str());
}

}  // namespace

Command add_bloom_command(CLI::App& app) {
  auto o = std::make_shared<BloomOptions>();
  CLI::App* sub =
      app.add_subcommand("bloom", "Apply bloom to an OpenEXR image; write RGBA half EXR (float with --fp32)");
  sub->add_option("input", o->input, "Input OpenEXR file (R,G,B[,A], or one grey channel)")->required();
  sub->add_option("output", o->output, "Output OpenEXR file (RGBA half; 32-bit float with --fp32)")->required();
  sub->add_option("--threshold", o->config.threshold, "Luminance where bloom starts (0 to 65504)");
  sub->add_option("--knee", o->config.soft_knee, "Soft knee width as a fraction of the threshold (0 to 1)");
  sub->add_option("--intensity", o->config.intensity, "Weight of the bloom added to the image (0 to 100)");
  sub->add_option("--iterations", o->config.iterations, "Pyramid levels (1 to 8; fewer at small sizes)");
  sub->add_option("--radius", o->config.radius, "Scale of the upsample footprint (0.25 to 4)");
  sub->add_option("--filter", o->filter, "Filter between levels")->check(CLI::IsMember({"cod13", "dual", "gauss9"}));
  sub->add_option("--firefly-guard", o->guard, "Firefly guard on the first downsample (docs/BLOOM.md)")
      ->check(CLI::IsMember({"off", "karis", "karis_smooth"}));
  sub->add_option("--max-brightness", o->config.max_brightness, "Per-channel clamp of level 0 (1e-3 to 8000)");
  sub->add_option("--level0-height", o->config.level0_height,
                  "Rows of pyramid level 0 (0 = half the input; 8 to 16384 makes the glow resolution independent)");
  sub->add_flag("--fp32", o->fp32,
                "Keep the pyramid and the output in RGBA32F and write 32-bit float EXR (default: RGBA16F, half EXR)");
  sub->add_option("--png", o->png, "Also write a tonemapped (ACES fitted) 8-bit sRGB PNG here");
  sub->add_option("--exposure", o->exposure, "Linear exposure applied before the PNG tonemap (> 0)");
  add_device_option(*sub, o->device);
  return {sub, [o] { run_bloom(*o); }};
}

}  // namespace glint::cli
