// glint demo: the built-in scene (tools/demo/demo_scene.h: a GPU-generated HDR starfield and sun, and a
// depth buffer with occluders and lights in front of and behind them), then lens flares (Hi-Z,
// cull, raster draw: LensFlarePass), then the default bloom, then the PNG tonemap; every stage in
// one command buffer, timed with GPU timestamps. Writes scene.exr, depth.exr (float Z),
// lights.json (which `glint flare` replays), flares.exr, bloom.exr and bloom.png.
#include <glint/bloom.h>
#include <glint/flare_pass.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>

#include "cli/commands.h"
#include "core/barriers.h"
#include "core/half.h"
#include "core/resources.h"
#include "demo/demo_scene.h"
#include "io/atomic_outputs.h"
#include "io/exr_io.h"
#include "io/lights_json.h"
#include "io/png_io.h"
#include "support/host_memory.h"
#include "support/transfer.h"

namespace glint::cli {
namespace {

struct DemoOptions {
  std::string size = "1920x1080";
  std::string out_dir = "out";
  std::string device;
  std::string preset = "cinematic";
  float exposure = 1.0f;
  uint32_t variant = 1;
};

void run_demo(const DemoOptions& o) {
  const auto wall_start = std::chrono::steady_clock::now();
  const VkExtent2D extent = parse_size("--size", o.size);
  // What the demo holds on the host at once, per pixel: the depth (4 bytes) and its EXR, three
  // read-back RGBA16F images staged (8 bytes each) and converted to float (16 bytes each), the
  // fill of the largest upload (16), the PNG (4) and the EXR writer's copy of one image (8).
  tools::check_host_memory("glint demo at " + o.size,
                           uint64_t(extent.width) * extent.height * (4 + 4 + 3 * (8 + 16) + 16 + 4 + 8));
  check_exposure(o.exposure);
  const FlareConfig look = flare_preset_from_name(o.preset);
  demo::StarfieldParams scene_params;
  scene_params.variant = o.variant;

  namespace fs = std::filesystem;
  std::error_code ec;
  fs::create_directories(o.out_dir, ec);
  if (ec || !fs::is_directory(o.out_dir)) {
    throw Error(ErrorCode::io_failure,
                o.out_dir + ": cannot create output directory" + (ec ? ": " + ec.message() : std::string()));
  }
  const auto out_path = [&](const char* name) { return (fs::path(o.out_dir) / name).string(); };

  const Context context = make_context(o.device);
  Bloom bloom(context);  // the default BloomConfig
  bloom.prepare(extent);
  const demo::FlareScene flare_scene = demo::make_flare_scene(extent);
  const auto n = static_cast<uint32_t>(flare_scene.lights.size());
  FlarePassConfig pc;
  pc.extent = extent;
  pc.cull.capacity = n;
  pc.cull.max_lights = n;
  pc.per_light_results = false;
  for (const auto& l : flare_scene.lights) pc.max_size_px = std::max(pc.max_size_px, l.size_px);
  LensFlarePass flares(context, pc);

  const VkImageUsageFlags usage = detail::kToolImageUsage | VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT;
  detail::OwnedImage scene(context, extent, VK_FORMAT_R16G16B16A16_SFLOAT, usage);
  detail::OwnedImage flared(context, extent, VK_FORMAT_R16G16B16A16_SFLOAT, usage);
  detail::OwnedImage result(context, extent, VK_FORMAT_R16G16B16A16_SFLOAT, detail::kToolImageUsage);
  detail::OwnedImage depth(context, extent, VK_FORMAT_D32_SFLOAT,
                           VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT);
  const VkDeviceSize light_bytes = VkDeviceSize(n) * sizeof(GlintFlareLight);
  const VkBufferUsageFlags light_usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
  detail::OwnedBuffer lights(context, light_bytes, light_usage, false);
  Buffer light_view{lights.buffer(), 0, light_bytes, light_usage, VK_PIPELINE_STAGE_2_NONE, VK_ACCESS_2_NONE};
  detail::OwnedBuffer light_up(context, light_bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, true);
  std::memcpy(light_up.mapped(), flare_scene.lights.data(), light_bytes);
  light_up.flush();
  const detail::OwnedBuffer depth_up = detail::make_upload_staging_r32(context, depth.image(), flare_scene.depth);
  const detail::OwnedBuffer scene_down = detail::make_readback_staging(context, scene.image());
  const detail::OwnedBuffer flared_down = detail::make_readback_staging(context, flared.image());
  const detail::OwnedBuffer result_down = detail::make_readback_staging(context, result.image());
  detail::OwnedBuffer stats_down(context, sizeof(GlintFlareStats), VK_BUFFER_USAGE_TRANSFER_DST_BIT, true);
  // The occluders are painted as dark silhouettes over the starfield: one staging buffer of a dark
  // RGBA16F colour as large as the largest box, copied into each box's rectangle.
  VkDeviceSize largest = 1;
  for (const VkRect2D& r : flare_scene.occluders)
    largest = std::max<VkDeviceSize>(largest, VkDeviceSize(r.extent.width) * r.extent.height);
  detail::OwnedBuffer silhouette(context, largest * 8, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, true);
  {
    const uint16_t dark[4] = {detail::float_to_half(0.012f), detail::float_to_half(0.014f),
                              detail::float_to_half(0.022f), detail::float_to_half(1.0f)};
    auto* px = static_cast<uint16_t*>(silhouette.mapped());
    for (VkDeviceSize i = 0; i < largest; ++i) std::memcpy(px + i * 4, dark, sizeof dark);
    silhouette.flush();
  }

  Profiler profiler(context);
  context.run_once([&](VkCommandBuffer cmd) {
    profiler.reset(cmd);
    profiler.mark(cmd, "start");
    detail::record_upload(cmd, depth_up, depth.image());
    detail::Barriers b;
    b.use(light_view, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT);
    b.flush(cmd);
    const VkBufferCopy lc{0, 0, light_bytes};
    vkCmdCopyBuffer(cmd, light_up.buffer(), lights.buffer(), 1, &lc);
    profiler.mark(cmd, "upload depth + lights");
    demo::record_starfield(context, cmd, scene.image(), scene_params, &profiler);
    if (!flare_scene.occluders.empty()) {
      b.use(scene.image(), VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_PIPELINE_STAGE_2_COPY_BIT,
            VK_ACCESS_2_TRANSFER_WRITE_BIT);
      b.flush(cmd);
      std::vector<VkBufferImageCopy> regions;
      for (const VkRect2D& r : flare_scene.occluders) {
        VkBufferImageCopy c{};
        c.bufferRowLength = r.extent.width;
        c.bufferImageHeight = r.extent.height;
        c.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
        c.imageOffset = {r.offset.x, r.offset.y, 0};
        c.imageExtent = {r.extent.width, r.extent.height, 1};
        regions.push_back(c);
      }
      vkCmdCopyBufferToImage(cmd, silhouette.buffer(), scene.image().image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                             static_cast<uint32_t>(regions.size()), regions.data());
      profiler.mark(cmd, "demo occluders");
    }
    // Flares go onto a copy, so that scene.exr keeps the scene alone.
    b.use(scene.image(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_PIPELINE_STAGE_2_COPY_BIT,
          VK_ACCESS_2_TRANSFER_READ_BIT);
    b.use(flared.image(), VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_PIPELINE_STAGE_2_COPY_BIT,
          VK_ACCESS_2_TRANSFER_WRITE_BIT);
    b.flush(cmd);
    VkImageCopy copy{};
    copy.srcSubresource = copy.dstSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    copy.extent = {extent.width, extent.height, 1};
    vkCmdCopyImage(cmd, scene.image().image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, flared.image().image,
                   VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &copy);
    profiler.mark(cmd, "copy scene");
    flares.record(cmd, flared.image(), depth.image(), light_view, n, flare_scene.view_proj.data(), look, &profiler);
    bloom.record(cmd, flared.image(), result.image(), &profiler);
    detail::record_readback(cmd, scene.image(), scene_down);
    detail::record_readback(cmd, flared.image(), flared_down);
    detail::record_readback(cmd, result.image(), result_down);
    b.use(flares.stats(), VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT);
    b.flush(cmd);
    const VkBufferCopy sc{0, 0, sizeof(GlintFlareStats)};
    vkCmdCopyBuffer(cmd, flares.stats().buffer, stats_down.buffer(), 1, &sc);
    Buffer down{stats_down.buffer(),           0, sizeof(GlintFlareStats), 0, VK_PIPELINE_STAGE_2_COPY_BIT,
                VK_ACCESS_2_TRANSFER_WRITE_BIT};
    b.use(down, VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT);
    b.flush(cmd);
  });
  const CpuImage scene_pixels = detail::read_staged(scene_down, scene.image());
  const CpuImage flared_pixels = detail::read_staged(flared_down, flared.image());
  const CpuImage result_pixels = detail::read_staged(result_down, result.image());
  stats_down.invalidate();
  GlintFlareStats st;
  std::memcpy(&st, stats_down.mapped(), sizeof st);

  std::printf("device: %s (%s)\n", context.info().name.c_str(), device_type_name(context.info().type));
  std::printf("scene: %ux%u RGBA16F starfield (variant %u), depth with 3 occluders, %u lights\n", extent.width,
              extent.height, o.variant, n);
  std::printf(
      "flares: preset %s, raster path, grid 4x4; lights: %u total, %u frustum-culled, %u occluded, %u visible "
      "(%u overflow), %u disabled\n",
      o.preset.c_str(), st.total, st.frustum_culled, st.occluded, st.visible, st.overflow, st.disabled);
  std::printf("bloom: default config, %u level%s%s\n", bloom.levels(), bloom.levels() == 1 ? "" : "s",
              bloom.clamped() ? " (clamped at this size)" : "");
  print_stages(profiler);

  // The six files are replaced together, only once all are written.
  io::AtomicOutputs files;
  files.write(out_path("scene.exr"), [&](const std::string& tmp) { io::write_exr_half(tmp, scene_pixels); });
  files.write(out_path("depth.exr"), [&](const std::string& tmp) {
    io::write_exr_channel(tmp, "Z", extent.width, extent.height, flare_scene.depth);
  });
  io::LightsFile lights_file;
  lights_file.view_proj = flare_scene.view_proj;
  lights_file.lights = flare_scene.lights;
  files.write(out_path("lights.json"),
              [&](const std::string& tmp) { io::write_text_file(tmp, io::to_lights_json(lights_file)); });
  files.write(out_path("flares.exr"), [&](const std::string& tmp) { io::write_exr_half(tmp, flared_pixels); });
  files.write(out_path("bloom.exr"), [&](const std::string& tmp) { io::write_exr_half(tmp, result_pixels); });
  files.write(out_path("bloom.png"),
              [&](const std::string& tmp) { io::write_png_tonemapped(tmp, result_pixels, o.exposure); });
  files.commit();
  const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  std::printf("wrote scene.exr, depth.exr, lights.json, flares.exr, bloom.exr, bloom.png in %s\n", o.out_dir.c_str());
  std::printf("wall time (device setup, pipelines, GPU, readback, files): %.2f s\n", wall_s);
}

}  // namespace

Command add_demo_command(CLI::App& app) {
  auto o = std::make_shared<DemoOptions>();
  CLI::App* sub = app.add_subcommand(
      "demo", "Render the built-in HDR starfield with occluders and lights, add lens flares, bloom, time each stage");
  sub->add_option("--size", o->size, "Image size WIDTHxHEIGHT");
  sub->add_option("--out", o->out_dir,
                  "Directory for scene.exr, depth.exr, lights.json, flares.exr, bloom.exr and bloom.png (created if "
                  "missing)");
  sub->add_option("--preset", o->preset, kFlarePresetHelp);
  sub->add_option("--exposure", o->exposure, "Linear exposure applied before the PNG tonemap (> 0)");
  sub->add_option("--variant,--seed", o->variant,
                  "Which random starfield (any 32-bit number; 1 by default; --seed is the same option)");
  add_device_option(*sub, o->device);
  return {sub, [o] { run_demo(*o); }};
}

}  // namespace glint::cli
