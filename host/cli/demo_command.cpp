// glint demo: the built-in scene (a GPU-generated HDR starfield and sun, host/demo_scene.h) with the
// default bloom, timed per stage with GPU timestamps; writes scene.exr, bloom.exr and bloom.png.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>

#include <glint/bloom.h>

#include "cli/commands.h"
#include "core/resources.h"
#include "core/transfer.h"
#include "demo_scene.h"
#include "io/exr_io.h"
#include "io/png_io.h"

namespace glint::cli {
namespace {

struct DemoOptions {
  std::string size = "1920x1080";
  std::string out_dir = "out";
  std::string device;
  float exposure = 1.0f;
  uint32_t seed = 1;
};

void run_demo(const DemoOptions& o) {
  const auto wall_start = std::chrono::steady_clock::now();
  const VkExtent2D extent = parse_size("--size", o.size);
  check_exposure(o.exposure);
  demo::StarfieldParams scene_params;
  scene_params.seed = o.seed;

  namespace fs = std::filesystem;
  std::error_code ec;
  fs::create_directories(o.out_dir, ec);
  if (ec || !fs::is_directory(o.out_dir)) {
    throw Error(ErrorCode::io_failure,
                o.out_dir + ": cannot create output directory" + (ec ? ": " + ec.message() : std::string()));
  }
  const std::string scene_path = (fs::path(o.out_dir) / "scene.exr").string();
  const std::string bloom_path = (fs::path(o.out_dir) / "bloom.exr").string();
  const std::string png_path = (fs::path(o.out_dir) / "bloom.png").string();

  ContextOptions options;
  options.device = o.device;
  const Context context = Context::create(options);
  Bloom bloom(context);  // the default BloomConfig
  bloom.prepare(extent);
  detail::OwnedImage scene(context, extent, VK_FORMAT_R16G16B16A16_SFLOAT, detail::kToolImageUsage);
  detail::OwnedImage result(context, extent, VK_FORMAT_R16G16B16A16_SFLOAT, detail::kToolImageUsage);
  Profiler profiler(context);
  context.run_once([&](VkCommandBuffer cmd) {
    profiler.reset(cmd);
    profiler.mark(cmd, "start");
    demo::record_starfield(context, cmd, scene.image(), scene_params, &profiler);
    bloom.record(cmd, scene.image(), result.image(), &profiler);
  });
  const CpuImage scene_pixels = detail::download(context, scene.image());
  const CpuImage result_pixels = detail::download(context, result.image());

  std::printf("device: %s (%s)\n", context.info().name.c_str(), device_type_name(context.info().type));
  std::printf("scene: %ux%u RGBA16F starfield (seed %u); bloom: default config, %u level%s%s\n", extent.width,
              extent.height, o.seed, bloom.levels(), bloom.levels() == 1 ? "" : "s",
              bloom.clamped() ? " (clamped at this size)" : "");
  print_stages(profiler);

  io::write_exr_half(scene_path, scene_pixels);
  io::write_exr_half(bloom_path, result_pixels);
  io::write_png_tonemapped(png_path, result_pixels, o.exposure);
  const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  std::printf("wrote %s, %s, %s\n", scene_path.c_str(), bloom_path.c_str(), png_path.c_str());
  std::printf("wall time (device setup, pipelines, GPU, readback, files): %.2f s\n", wall_s);
}

}  // namespace

Command add_demo_command(CLI::App& app) {
  auto o = std::make_shared<DemoOptions>();
  CLI::App* sub = app.add_subcommand("demo", "Render the built-in HDR starfield, bloom it, time each stage");
  sub->add_option("--size", o->size, "Image size WIDTHxHEIGHT");
  sub->add_option("--out", o->out_dir, "Directory for scene.exr, bloom.exr and bloom.png (created if missing)");
  sub->add_option("--exposure", o->exposure, "Linear exposure applied before the PNG tonemap (> 0)");
  sub->add_option("--seed", o->seed, "Seed of the starfield");
  add_device_option(*sub, o->device);
  return {sub, [o] { run_demo(*o); }};
}

}  // namespace glint::cli
