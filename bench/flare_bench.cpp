// Lens-flare draw benchmarks: GPU time from timestamp queries as manual time (CONTRIBUTING.md,
// "Benchmarks") for the raster path (one vkCmdDrawIndirect) and the compute path (indirect
// gather) into a 1920x1080 RGBA16F image, for 10 lights (budget 50 us, docs/PERF.md) and 1000
// lights. The instance and indirect buffers are device-local and filled once, as the cull would
// leave them; the frame measured is the draw alone.
//
// Light sizes (argument `sizes`):
// - 0, the first configuration: 10 lights of 40 to 160 px (around the default flare size of
//   100 px), 1000 lights of 8 to 48 px (street lamps in the distance).
// - 1, mixed: sizes log-uniform over 10 to 100 px, the lower part of the 10 to 500 px range
//   docs/FLARE.md designs for (a typical scene: 10 to 20 lights of mixed sizes). Each light covers about 22 size^2
//   pixels with its nine sprites (docs/FLARE.md), so the 10 lights of configuration 0 cover 2.06 M sprite pixels, 40
//   times a naive "100x100 quad x 10 lights, half covered" estimate.
// 0 lights measures the fixed cost of each path.
//
// Counters: median_us, sprite_pixels (pixels the sprites cover on screen, from the float64
// reference's sprite geometry: the fill work), fill_pixels_per_second and, for the compute path,
// how that work falls on the gather's tiles (tile_load below): tile_sprites_max,
// tile_sprites_mean and invocation_samples_max.
#include <benchmark/benchmark.h>
#include <glint/flare.h>
#include <glint/gpu/flare_types.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>
#include <string>

#include "bench_support.h"
#include "core/barriers.h"
#include "core/pipeline.h"
#include "core/resources.h"
#include "flare/flare_internal.h"
#include "flare/shaders/flare_params.h"
#include "reference/flare_reference.h"
#include "support/transfer.h"

namespace glint::bench {
namespace {

constexpr int kFramesPerIteration = 16;

// Lights spread over the screen with HDR colours and partial visibility; sizes as above.
std::vector<GlintFlareInstance> bench_lights(uint32_t n, uint32_t width, uint32_t height, bool mixed) {
  std::mt19937 rng(42);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  const float lo = mixed ? 10.0f : n <= 10 ? 40.0f : 8.0f, hi = mixed ? 100.0f : n <= 10 ? 160.0f : 48.0f;
  std::vector<GlintFlareInstance> out(n);
  for (uint32_t i = 0; i < n; ++i) {
    GlintFlareInstance& g = out[i];
    g.center_x_px = width * unit(rng);
    g.center_y_px = height * unit(rng);
    g.size_px = mixed ? lo * std::pow(hi / lo, unit(rng)) : lo + (hi - lo) * unit(rng);
    g.visible_fraction = 0.25f + 0.75f * unit(rng);
    g.color_r = 1.0f + 4.0f * unit(rng);
    g.color_g = 1.0f + 4.0f * unit(rng);
    g.color_b = 1.0f + 4.0f * unit(rng);
    g.intensity = 1.0f + 2.0f * unit(rng);
    g.light_index = i;
    g.element = GLINT_FLARE_ELEMENT_GLOW;
  }
  return out;
}

// How the compute draw's work falls on its tiles, from the float64 reference's sprite geometry: the
// most and the mean sprites a tile lists (each sprite's rectangle widened by the 2-pixel margin of
// glint_flare_sprite_bounds) and the most samples one invocation shades (the pixels of its column
// in its tile, rows `tile.row_step` apart, that a sprite lights). The gather's dispatch lasts as long as
// its slowest tile.
struct TileLoad {
  double sprites_max = 0, sprites_mean = 0, samples_max = 0;
};

TileLoad tile_load(const std::vector<reference::FlareSprite>& sprites, uint32_t width, uint32_t height,
                   detail::FlareGatherTile tile) {
  const uint32_t tx = (width + tile.width - 1) / tile.width, ty = (height + tile.height - 1) / tile.height;
  std::vector<uint32_t> listed(size_t(tx) * ty, 0), samples(size_t(width) * height, 0);
  for (const auto& s : sprites) {
    if (!(s.width > 0.0)) continue;
    const double x0 = s.lo_x - 2.0, x1 = s.lo_x + s.width + 2.0, y0 = s.lo_y - 2.0, y1 = s.lo_y + s.height + 2.0;
    for (uint32_t j = 0; j < ty; ++j) {
      for (uint32_t i = 0; i < tx; ++i) {
        if (x0 < double(i + 1) * tile.width && x1 > double(i) * tile.width && y0 < double(j + 1) * tile.height &&
            y1 > double(j) * tile.height) {
          ++listed[size_t(j) * tx + i];
        }
      }
    }
    // Pixel p is lit when its centre p + 0.5 lies in [lo, lo + size).
    const auto first = [](double lo) { return std::max(0.0, std::ceil(lo - 0.5)); };
    const auto end = [](double hi, uint32_t n) { return std::min(double(n), std::ceil(hi - 0.5)); };
    for (double y = first(s.lo_y); y < end(s.lo_y + s.height, height); ++y) {
      for (double x = first(s.lo_x); x < end(s.lo_x + s.width, width); ++x) ++samples[size_t(y) * width + size_t(x)];
    }
  }
  TileLoad load;
  for (uint32_t v : listed) {
    load.sprites_max = std::max(load.sprites_max, double(v));
    load.sprites_mean += double(v) / double(listed.size());
  }
  for (uint32_t y0 = 0; y0 < height; y0 += tile.height) {
    for (uint32_t row = 0; row < tile.row_step; ++row) {
      for (uint32_t x = 0; x < width; ++x) {
        double sum = 0;
        for (uint32_t y = y0 + row; y < std::min(y0 + tile.height, height); y += tile.row_step)
          sum += samples[size_t(y) * width + x];
        load.samples_max = std::max(load.samples_max, sum);
      }
    }
  }
  return load;
}

// The draw of `lights` instances (an instances buffer of exactly that many) into a width x height
// RGBA16F image, the compute path with its dispatches chosen by `path`; `split` 0 or 1 makes every
// pre-pass draw split no tile or the crowded ones (-1: as the device and buffer choose).
void run_flare_draw(benchmark::State& state, uint32_t width, uint32_t height, uint32_t lights, bool compute, bool mixed,
                    detail::FlareGatherPath path, int split = -1, detail::Workgroup2D gather_workgroup = {0, 0},
                    const uint32_t* split_params = nullptr, uint32_t one_dispatch_rows = 0) {
  const Context& ctx = context();
  const VkFormat format = VK_FORMAT_R16G16B16A16_SFLOAT;

  detail::OwnedImage color(ctx, {width, height}, format, detail::kToolImageUsage | VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT);
  detail::upload(ctx, color.state, random_hdr(width, height, 7));
  LensFlare flare(ctx, format, {width, height});
  detail::LensFlareAccess::select_gather(flare, path);
  if (split >= 0) detail::LensFlareAccess::set_split(flare, split == 1);
  if (split_params) detail::LensFlareAccess::set_split(flare, true, split_params[0], split_params[1], split_params[2]);
  if (gather_workgroup.x != 0 || one_dispatch_rows != 0) {
    // The one-dispatch gather's shape when that path is forced, else the pre-pass gathers'.
    const bool one = path == detail::FlareGatherPath::one_dispatch;
    const detail::FlareGatherTile t = detail::LensFlareAccess::gather_tile(flare, one, lights);
    const detail::Workgroup2D g = gather_workgroup.x != 0 ? gather_workgroup : detail::Workgroup2D{t.width, t.row_step};
    detail::LensFlareAccess::set_gather_workgroup(flare, g.x, g.y, one, one_dispatch_rows);
  }
  const FlareConfig config = FlareConfig::preset(FlarePreset::cinematic);

  const std::vector<GlintFlareInstance> list = bench_lights(lights, width, height, mixed);
  GlintFlareIndirect args{};
  args.vertex_count = LensFlare::vertices_per_instance();
  args.instance_count = lights;
  args.group_count_x = lights * flare.groups_per_instance();
  args.group_count_y = args.group_count_z = 1;
  const VkBufferUsageFlags usage =
      VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
  const VkDeviceSize instance_bytes = std::max<size_t>(list.size(), 1) * sizeof(GlintFlareInstance);
  detail::OwnedBuffer instances(ctx, instance_bytes, usage, false);
  detail::OwnedBuffer indirect(ctx, sizeof(args), usage, false);
  detail::OwnedBuffer staging(ctx, instance_bytes + sizeof(args), VK_BUFFER_USAGE_TRANSFER_SRC_BIT, true);
  std::memset(staging.mapped(), 0, instance_bytes);
  if (!list.empty()) std::memcpy(staging.mapped(), list.data(), list.size() * sizeof(GlintFlareInstance));
  std::memcpy(static_cast<uint8_t*>(staging.mapped()) + instance_bytes, &args, sizeof(args));
  staging.flush();
  Buffer inst{
      instances.buffer(), 0, instance_bytes, usage, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT};
  Buffer ind{indirect.buffer(), 0, sizeof(args), usage, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT};
  ctx.run_once([&](VkCommandBuffer cmd) {
    VkBufferCopy a{0, 0, instance_bytes}, b{instance_bytes, 0, sizeof(args)};
    vkCmdCopyBuffer(cmd, staging.buffer(), instances.buffer(), 1, &a);
    vkCmdCopyBuffer(cmd, staging.buffer(), indirect.buffer(), 1, &b);
  });

  auto frame = [&](VkCommandBuffer cmd, Profiler* p) {
    if (compute) {
      flare.record_compute(cmd, color.state, inst, ind, config, p);
    } else {
      flare.record_raster(cmd, color.state, inst, ind, config, p);
    }
  };
  ctx.run_once([&](VkCommandBuffer cmd) { frame(cmd, nullptr); });  // warm-up: descriptor sets, caches

  Profiler profiler(ctx, kFramesPerIteration + 1);
  std::vector<double> frame_ms;
  for (auto _ : state) {
    const double median =
        median_frame_ms(ctx, profiler, kFramesPerIteration, [&](VkCommandBuffer cmd) { frame(cmd, nullptr); });
    frame_ms.push_back(median);
    state.SetIterationTime(median * 1e-3);
  }
  double pixels = 0;  // on-screen area of every sprite (the fill work of either path)
  std::vector<reference::FlareSprite> sprites;
  for (const auto& g : list) {
    for (uint32_t slot = 0; slot < GLINT_FLARE_SPRITES; ++slot) {
      const auto s = reference::flare_sprite(g, slot, config, width, height);
      sprites.push_back(s);
      const double w = std::clamp(s.lo_x + s.width, 0.0, double(width)) - std::clamp(s.lo_x, 0.0, double(width));
      const double h = std::clamp(s.lo_y + s.height, 0.0, double(height)) - std::clamp(s.lo_y, 0.0, double(height));
      pixels += std::max(w, 0.0) * std::max(h, 0.0);
    }
  }
  state.counters["median_us"] = median_of(frame_ms) * 1e3;
  state.counters["lights"] = lights;
  state.counters["sprite_pixels"] = pixels;
  state.counters["fill_pixels_per_second"] = benchmark::Counter(pixels, benchmark::Counter::kIsIterationInvariantRate);
  // As record_compute() decides: a gather workgroup of fewer than GLINT_FLARE_SPRITES invocations
  // (ContextOptions::workgroup_2d can force one) holds no instance's sprites and takes the pre-pass.
  const detail::FlareGatherTile one_tile = detail::LensFlareAccess::gather_tile(flare, true, lights);
  const bool one_dispatch = one_tile.width * one_tile.row_step >= GLINT_FLARE_SPRITES &&
                            (path == detail::FlareGatherPath::one_dispatch ||
                             (path == detail::FlareGatherPath::device && lights <= flare.one_dispatch_instances()));
  if (compute) {
    const TileLoad load =
        tile_load(sprites, width, height, detail::LensFlareAccess::gather_tile(flare, one_dispatch, lights));
    state.counters["tile_sprites_max"] = load.sprites_max;
    state.counters["tile_sprites_mean"] = load.sprites_mean;
    state.counters["invocation_samples_max"] = load.samples_max;
  }
  const bool splits = detail::LensFlareAccess::splits(flare, lights);
  state.SetLabel(std::string(compute ? (one_dispatch ? "compute, one dispatch"
                                        : splits     ? "compute, pre-pass, crowded tiles split"
                                                     : "compute, pre-pass")
                                     : "raster") +
                 (mixed ? " mixed sizes" : "") + " rgba16f on " + ctx.info().name);
}

void BM_FlareDraw(benchmark::State& state) {
  run_flare_draw(state, static_cast<uint32_t>(state.range(0)), static_cast<uint32_t>(state.range(1)),
                 static_cast<uint32_t>(state.range(2)), state.range(3) != 0, state.range(4) != 0,
                 detail::FlareGatherPath::device);
}

BENCHMARK(BM_FlareDraw)
    ->Args({1920, 1080, 10, 0, 0})
    ->Args({1920, 1080, 10, 1, 0})
    ->Args({1920, 1080, 1000, 0, 0})
    ->Args({1920, 1080, 1000, 1, 0})
    ->Args({1920, 1080, 10, 0, 1})
    ->Args({1920, 1080, 10, 1, 1})
    ->Args({1920, 1080, 0, 0, 0})
    ->Args({1920, 1080, 0, 1, 0})
    ->ArgNames({"w", "h", "lights", "compute", "sizes"})
    ->UseManualTime()
    ->Unit(benchmark::kMicrosecond);

// The compute draw's two structures on the same lights (1920x1080, mixed sizes), whatever the
// instance count would choose: path 1 the launch arguments, sprite pre-pass and gather, path 2 the
// one-dispatch gather that evaluates the sprites itself (LensFlare::one_dispatch_instances()).
void BM_FlareGatherPath(benchmark::State& state) {
  run_flare_draw(state, 1920, 1080, static_cast<uint32_t>(state.range(0)), true, true,
                 state.range(1) == 1 ? detail::FlareGatherPath::pre_pass : detail::FlareGatherPath::one_dispatch);
}

BENCHMARK(BM_FlareGatherPath)
    ->ArgsProduct({{10, 28, 64, 128, 256, 1000}, {1, 2}})
    ->ArgNames({"lights", "path"})
    ->UseManualTime()
    ->Unit(benchmark::kMicrosecond);

// The pre-pass draw without and with the split of crowded tiles (1920x1080, mixed sizes), whatever
// the instances buffer would choose (GLINT_FLARE_SPLIT_FROM_INSTANCES).
void BM_FlareSplit(benchmark::State& state) {
  run_flare_draw(state, 1920, 1080, static_cast<uint32_t>(state.range(0)), true, true,
                 detail::FlareGatherPath::pre_pass, static_cast<int>(state.range(1)));
}

BENCHMARK(BM_FlareSplit)
    ->ArgsProduct({{256, 512, 1000}, {0, 1}})
    ->ArgNames({"lights", "split"})
    ->UseManualTime()
    ->Unit(benchmark::kMicrosecond);

// The compute draw (1920x1080, mixed sizes unless `mixed` is 0) with a gather in other workgroup
// shapes: the pre-pass gathers (one:0; light counts that take them) or the one-dispatch gather
// (one:1, forced, with `rows` rows per invocation, 0 its default) in shape 0 the device's (32x8 on
// GPUs), 1 16x8, 2 16x16, 3 64x4, 4 8x16, 5 32x8, 6 8x32; the split as the instances buffer
// decides. (Before the gathers had shapes of their own, e784eea's one:0 rows of 10 lights set the
// one-dispatch gather's shape too.)
void BM_FlareGatherShape(benchmark::State& state) {
  static const detail::Workgroup2D kShapes[] = {{0, 0}, {16, 8}, {16, 16}, {64, 4}, {8, 16}, {32, 8}, {8, 32}};
  const detail::Workgroup2D g = kShapes[state.range(3)];
  if (g.x * g.y > context().info().max_workgroup_invocations) {
    state.SkipWithError("the shape exceeds the device's maxComputeWorkGroupInvocations");
    return;
  }
  const bool one = state.range(2) != 0;
  run_flare_draw(state, 1920, 1080, static_cast<uint32_t>(state.range(0)), true, state.range(1) != 0,
                 one ? detail::FlareGatherPath::one_dispatch : detail::FlareGatherPath::device, -1, g, nullptr,
                 static_cast<uint32_t>(state.range(4)));
}

BENCHMARK(BM_FlareGatherShape)
    ->ArgsProduct({{1000}, {0}, {0}, {0, 1, 2, 3, 4}, {0}})
    ->ArgsProduct({{256, 1000}, {1}, {0}, {0, 1, 2, 3, 4}, {0}})
    ->ArgsProduct({{10}, {0}, {1}, {0, 2, 5, 6}, {0, 2, 4}})
    ->ArgsProduct({{16}, {1}, {1}, {0, 5}, {0}})
    ->ArgNames({"lights", "mixed", "one", "shape", "rows"})
    ->UseManualTime()
    ->Unit(benchmark::kMicrosecond);

// The split draw of 1000 lights (1920x1080; mixed sizes with mixed:1) under other split
// parameters (tiles of min_sprites sprites and more split, sprites per slice, most slices): 0 the
// defaults (flare_params.h), then {128, 64, 16}, {256, 32, 16}, {256, 32, 31}, {128, 32, 31},
// {512, 64, 16}.
void BM_FlareSplitParams(benchmark::State& state) {
  static const uint32_t kParams[][3] = {
      {GLINT_FLARE_SPLIT_MIN_SPRITES, GLINT_FLARE_SPLIT_SPRITES, GLINT_FLARE_SPLIT_MAX_SLICES},
      {128, 64, 16},
      {256, 32, 16},
      {256, 32, 31},
      {128, 32, 31},
      {512, 64, 16}};
  run_flare_draw(state, 1920, 1080, 1000, true, state.range(0) != 0, detail::FlareGatherPath::pre_pass, 1, {0, 0},
                 kParams[state.range(1)]);
}

BENCHMARK(BM_FlareSplitParams)
    ->ArgsProduct({{0, 1}, {0, 1, 2, 3, 4, 5}})
    ->ArgNames({"mixed", "params"})
    ->UseManualTime()
    ->Unit(benchmark::kMicrosecond);

// Atlas generation at start-up (every level), for the record: it runs once per LensFlare.
void BM_FlareAtlas(benchmark::State& state) {
  const Context& ctx = context();
  Profiler profiler(ctx, 2);
  std::vector<double> ms;
  for (auto _ : state) {
    LensFlare flare(ctx, VK_FORMAT_R16G16B16A16_SFLOAT, {64, 64});  // generates once here
    Context adopted = Context::adopt(
        {ctx.instance(), VK_API_VERSION_1_3, ctx.physical_device(), ctx.device(), ctx.queue_family_index()});
    LensFlare lazy(adopted, VK_FORMAT_R16G16B16A16_SFLOAT, {64, 64});
    ctx.run_once([&](VkCommandBuffer cmd) {
      profiler.reset(cmd);
      profiler.mark(cmd, "start");
      lazy.record_setup(cmd);
      profiler.mark(cmd, "atlas");
    });
    const double t = profiler.total_ms();
    ms.push_back(t);
    state.SetIterationTime(t * 1e-3);
  }
  state.counters["median_us"] = median_of(ms) * 1e3;
  state.counters["texels"] = double(GLINT_FLARE_ATLAS_WIDTH) * GLINT_FLARE_ATLAS_HEIGHT;
  state.SetLabel("on " + ctx.info().name);
}

BENCHMARK(BM_FlareAtlas)->UseManualTime()->Unit(benchmark::kMicrosecond)->Iterations(5);

}  // namespace
}  // namespace glint::bench
