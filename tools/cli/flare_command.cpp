// glint flare --color IN.exr --depth DEPTH.exr --lights LIGHTS.json OUT.exr: lens flares with
// GPU visibility. One command buffer holds the whole frame: the uploads, the Hi-Z
// build, the cull + occlusion grid + compaction, the draw (raster or compute) and the readbacks
// (image, statistics, per-light results); nothing is read back between the stages.
//
// STATS.json (--stats): {"total", "frustum_culled", "occluded", "visible", "overflow", "disabled",
// "lights": [{"visible_fraction": f, "culled": null | "frustum" | "occluded" | "disabled" |
// "overflow"}, ...]} with one entry per input light in input order. "visible" counts every light
// that passed the occlusion test, including those the instance buffer had no room for
// ("overflow"); those are not drawn and report visible_fraction 0, like every culled light.
#include <glint/flare_pass.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <sstream>

#include "cli/commands.h"
#include "core/barriers.h"
#include "core/resources.h"
#include "io/atomic_outputs.h"
#include "io/exr_io.h"
#include "io/lights_json.h"
#include "support/transfer.h"

namespace glint::cli {
namespace {

struct FlareOptions {
  std::string color, depth, lights, output, stats, device;
  std::string preset = "cinematic";
  std::string draw = "raster";
  uint32_t grid = 4;
  bool reverse_z = false;
  bool fp32 = false;
};

const char* culled_name(uint32_t culled) {
  switch (culled) {
    case GLINT_FLARE_FRUSTUM:
      return "\"frustum\"";
    case GLINT_FLARE_OCCLUDED:
      return "\"occluded\"";
    case GLINT_FLARE_DISABLED:
      return "\"disabled\"";
    case GLINT_FLARE_OVERFLOW:
      return "\"overflow\"";
    default:
      return "null";  // GLINT_FLARE_VISIBLE
  }
}

// The text of STATS.json (format at the top of this file).
std::string stats_json(const GlintFlareStats& s, const GlintFlareLightResult* results, size_t n) {
  std::ostringstream out;
  out << "{\"total\": " << s.total << ", \"frustum_culled\": " << s.frustum_culled << ", \"occluded\": " << s.occluded
      << ", \"visible\": " << s.visible << ", \"overflow\": " << s.overflow << ", \"disabled\": " << s.disabled
      << ",\n \"lights\": [";
  char num[32];
  for (size_t i = 0; i < n; ++i) {
    // %.9g round-trips a float; fractions are multiples of 1/N^2, so most print short.
    std::snprintf(num, sizeof num, "%.9g", double(results[i].visible_fraction));
    out << (i ? ",\n  " : "\n  ") << "{\"visible_fraction\": " << num
        << ", \"culled\": " << culled_name(results[i].culled) << "}";
  }
  out << (n ? "\n ]}\n" : "]}\n");
  return out.str();
}

void run_flare(const FlareOptions& o) {
  // Flags and output paths first: a typo costs no file reading and no device.
  const FlareConfig look = flare_preset_from_name(o.preset);
  if (o.grid < 1 || o.grid > 16) {
    throw Error(ErrorCode::invalid_argument,
                "--grid = " + std::to_string(o.grid) + " is out of range: accepted 1 to 16 (N x N cells per light)");
  }
  check_output_path(o.output);
  if (!o.stats.empty()) {
    check_output_path(o.stats);
    check_distinct_outputs({"OUT", "--stats"}, {o.output, o.stats});
  }

  const CpuImage color_in = io::read_exr(o.color);
  const io::ExrChannel depth_in = read_depth_exr(o.depth);
  if (depth_in.width != color_in.width || depth_in.height != color_in.height) {
    throw Error(ErrorCode::invalid_argument, "--depth " + o.depth + " is " + std::to_string(depth_in.width) + "x" +
                                                 std::to_string(depth_in.height) + " but --color " + o.color + " is " +
                                                 std::to_string(color_in.width) + "x" +
                                                 std::to_string(color_in.height) + "; the sizes must match");
  }
  const io::LightsFile lights = io::load_lights_json(o.lights);
  const auto n = static_cast<uint32_t>(lights.lights.size());
  float max_size = 1.0f;
  for (const auto& l : lights.lights) max_size = std::max(max_size, l.size_px);

  const Context context = make_context(o.device);
  const VkExtent2D extent{color_in.width, color_in.height};
  FlarePassConfig pc;
  pc.extent = extent;
  pc.color_format = o.fp32 ? VK_FORMAT_R32G32B32A32_SFLOAT : VK_FORMAT_R16G16B16A16_SFLOAT;
  pc.depth_format = VK_FORMAT_D32_SFLOAT;
  pc.reversed_z = o.reverse_z;
  pc.cull.grid = o.grid;
  pc.cull.capacity = std::max(n, 1u);  // every light can be drawn (compute: up to the device's limit)
  pc.cull.max_lights = std::max(n, 1u);
  pc.max_size_px = max_size;
  pc.draw = o.draw == "compute" ? FlareDrawPath::compute : FlareDrawPath::raster;
  pc.clamp_capacity = true;
  pc.per_light_results = !o.stats.empty();
  LensFlarePass pass(context, pc);

  const VkImageUsageFlags color_usage = detail::kToolImageUsage | VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT;
  detail::OwnedImage color(context, extent, pc.color_format, color_usage);
  detail::OwnedImage depth(context, extent, pc.depth_format,
                           VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT);
  const VkBufferUsageFlags light_usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
  const VkDeviceSize light_bytes = std::max<VkDeviceSize>(VkDeviceSize(n) * sizeof(GlintFlareLight), 16);
  detail::OwnedBuffer light_buffer(context, light_bytes, light_usage, false);
  Buffer light_view{light_buffer.buffer(), 0, light_bytes, light_usage, VK_PIPELINE_STAGE_2_NONE, VK_ACCESS_2_NONE};

  // Staging: colour, depth and lights in; colour, statistics and results out.
  const detail::OwnedBuffer color_up = detail::make_upload_staging(context, color.image(), color_in);
  const detail::OwnedBuffer depth_up = detail::make_upload_staging_r32(context, depth.image(), depth_in.values);
  detail::OwnedBuffer light_up(context, light_bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, true);
  if (n) std::memcpy(light_up.mapped(), lights.lights.data(), size_t(n) * sizeof(GlintFlareLight));
  light_up.flush();
  const detail::OwnedBuffer color_down = detail::make_readback_staging(context, color.image());
  const VkDeviceSize results_bytes = VkDeviceSize(n) * sizeof(GlintFlareLightResult);
  detail::OwnedBuffer stats_down(context, sizeof(GlintFlareStats) + results_bytes, VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                 true);

  Profiler profiler(context);
  context.run_once([&](VkCommandBuffer cmd) {
    profiler.reset(cmd);
    profiler.mark(cmd, "start");
    detail::record_upload(cmd, color_up, color.image());
    detail::record_upload(cmd, depth_up, depth.image());
    detail::Barriers b;
    b.use(light_view, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT);
    b.flush(cmd);
    const VkBufferCopy lc{0, 0, light_bytes};
    vkCmdCopyBuffer(cmd, light_up.buffer(), light_buffer.buffer(), 1, &lc);
    profiler.mark(cmd, "upload");

    pass.record(cmd, color.image(), depth.image(), light_view, n, lights.view_proj.data(), look, &profiler);

    detail::record_readback(cmd, color.image(), color_down);
    Buffer& stats = pass.stats();
    b.use(stats, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT);
    if (pc.per_light_results) b.use(pass.results(), VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT);
    b.flush(cmd);
    const VkBufferCopy sc{0, 0, sizeof(GlintFlareStats)};
    vkCmdCopyBuffer(cmd, stats.buffer, stats_down.buffer(), 1, &sc);
    if (pc.per_light_results && n) {
      const VkBufferCopy rc{0, sizeof(GlintFlareStats), results_bytes};
      vkCmdCopyBuffer(cmd, pass.results().buffer, stats_down.buffer(), 1, &rc);
    }
    Buffer down{stats_down.buffer(),           0, stats_down.size(), 0, VK_PIPELINE_STAGE_2_COPY_BIT,
                VK_ACCESS_2_TRANSFER_WRITE_BIT};
    b.use(down, VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT);
    b.flush(cmd);
    profiler.mark(cmd, "readback");
  });
  const CpuImage result = detail::read_staged(color_down, color.image());
  stats_down.invalidate();
  GlintFlareStats st;
  std::memcpy(&st, stats_down.mapped(), sizeof st);
  const auto* results =
      reinterpret_cast<const GlintFlareLightResult*>(static_cast<const char*>(stats_down.mapped()) + sizeof st);

  std::printf("device: %s (%s)\n", context.info().name.c_str(), device_type_name(context.info().type));
  std::printf("input: %s + %s (channel %s), %ux%u; %u light%s from %s\n", o.color.c_str(), o.depth.c_str(),
              depth_in.name.c_str(), extent.width, extent.height, n, n == 1 ? "" : "s", o.lights.c_str());
  std::printf("flare: preset %s, %s path, grid %ux%u, %s Z, capacity %u\n", o.preset.c_str(), o.draw.c_str(), o.grid,
              o.grid, o.reverse_z ? "reversed" : "standard", pass.config().cull.capacity);
  std::printf("lights: %u total, %u frustum-culled, %u occluded, %u visible (%u overflow), %u disabled\n", st.total,
              st.frustum_culled, st.occluded, st.visible, st.overflow, st.disabled);
  print_stages(profiler);

  io::AtomicOutputs files;  // OUT and --stats are replaced together, only once both are written
  files.write(o.output, [&](const std::string& tmp) { io::write_exr_half(tmp, result); });
  if (!o.stats.empty()) {
    const std::string text = stats_json(st, results, pc.per_light_results ? n : 0);
    files.write(o.stats, [&](const std::string& tmp) { io::write_text_file(tmp, text); });
  }
  files.commit();
  for (const std::string& f : files.targets()) std::printf("wrote %s\n", f.c_str());
}

}  // namespace

Command add_flare_command(CLI::App& app) {
  auto o = std::make_shared<FlareOptions>();
  CLI::App* sub = app.add_subcommand(
      "flare", "Add lens flares of a light list to an OpenEXR image, with visibility from a depth image (on the GPU)");
  sub->add_option("--color", o->color, "HDR input OpenEXR file (R,G,B[,A], or one grey channel)")->required();
  sub->add_option("--depth", o->depth,
                  "Depth OpenEXR file, same size: one float channel named Z (else the first channel), values in [0, 1]")
      ->required();
  sub->add_option("--lights", o->lights,
                  "LIGHTS.json: {\"view_proj\": [16 numbers, column-major], \"lights\": [{\"position\": [x,y,z], "
                  "\"color\": [r,g,b], \"intensity\": f, \"size\": px, \"element\": \"glow\", \"enabled\": true}]}")
      ->required();
  sub->add_option("output", o->output, "Output OpenEXR file (RGBA half)")->required();
  sub->add_option("--preset", o->preset, kFlarePresetHelp);
  sub->add_option("--grid", o->grid, "Occlusion grid: N x N samples per light (1 to 16)");
  sub->add_flag("--reverse-z", o->reverse_z, "Depth 1 is near and 0 far (reversed Z)");
  sub->add_option("--draw", o->draw, "Drawing path")->check(CLI::IsMember({"raster", "compute"}));
  sub->add_option("--stats", o->stats, "Write the cull's statistics and one result per light as JSON here");
  sub->add_flag("--fp32", o->fp32,
                "Draw into an RGBA32F image instead of RGBA16F (the output file is half either way)");
  add_device_option(*sub, o->device);
  return {sub, [o] { run_flare(*o); }};
}

}  // namespace glint::cli
