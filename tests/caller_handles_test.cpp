// Effects keep nothing that names the caller's views or buffers: descriptors are pushed with each
// dispatch (VK_KHR_push_descriptor). Vulkan may give a new object the handle of a destroyed one
// (lavapipe does for an object of the same size: its handles are pointers); an effect that cached
// descriptor sets by handle would bind the destroyed object's descriptors for the new one and read
// and write freed memory (lavapipe crashed that way), leaving the new output poisoned. Each test
// records, destroys the caller's objects, makes new ones with other contents, records again with
// no call in between and compares with the float64 reference: on the validated context of the
// suite (support/gpu_test.h fails a test on any message) and on a context without validation,
// because the validation layer wraps every handle in a unique id and so hides handle reuse.
#include <glint/bloom.h>
#include <glint/blur.h>
#include <glint/lod.h>
#include <glint/occlusion.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "core/barriers.h"
#include "reference/bloom_reference.h"
#include "reference/blur_reference.h"
#include "reference/occlusion_reference.h"
#include "support/environment.h"
#include "support/gpu_test.h"
#include "support/transfer.h"

namespace glint::test {
namespace {

constexpr VkFormat kF32 = VK_FORMAT_R32G32B32A32_SFLOAT;

class CallerHandlesTest : public GpuTest {};

// The suite's context, then one on the same device without validation (raw driver handles).
std::vector<const Context*> contexts() {
  static const std::unique_ptr<Context> raw = [] {
    ContextOptions options = tools::context_options_from_environment();
    options.validation = false;
    options.gpu_assisted_validation = false;
    return std::make_unique<Context>(Context::create(options));
  }();
  return {&context(), raw.get()};
}

std::string name_of(const Context& ctx) { return &ctx == &context() ? "validated context" : "raw handles"; }

// Runs `record` on a new input made from `pixels` into a new NaN-poisoned output on `ctx`, reads the
// output back and destroys both; `handles` gets the two views' handles.
template <typename Record>
CpuImage run_once_with_new_images(const Context& ctx, const CpuImage& pixels, std::vector<VkImageView>& handles,
                                  Record&& record) {
  detail::OwnedImage in(ctx, {pixels.width, pixels.height}, kF32, detail::kToolImageUsage);
  detail::upload(ctx, in.state, pixels);
  detail::OwnedImage out(ctx, {pixels.width, pixels.height}, kF32, detail::kToolImageUsage);
  detail::fill(ctx, out.state, std::nanf(""));
  handles = {in.state.view, out.state.view};
  ctx.run_once([&](VkCommandBuffer cmd) { record(cmd, in.state, out.state); });
  return detail::download(ctx, out.state);
}

// How many of `now`'s handles were handles of `before`'s objects.
uint32_t reused(const std::vector<VkImageView>& before, const std::vector<VkImageView>& now) {
  uint32_t n = 0;
  for (VkImageView v : now) n += std::find(before.begin(), before.end(), v) != before.end();
  return n;
}

// fp32 input, levels and output: relative L2 within 1e-3 of the reference (the bloom tests'
// fp32 tolerance, bloom_test.cpp).
TEST_F(CallerHandlesTest, BloomIsCorrectWithNewViewsOfDestroyedOnesHandles) {
  for (const Context* ctx : contexts()) {
    Bloom bloom(*ctx);
    std::vector<VkImageView> before, now;
    uint32_t reuses = 0;
    for (uint32_t round = 0; round < 4; ++round) {
      const CpuImage input = random_hdr(61, 37, 100 + round);
      const CpuImage gpu = run_once_with_new_images(
          *ctx, input, now, [&](VkCommandBuffer cmd, Image& in, Image& out) { bloom.record(cmd, in, out); });
      ASSERT_TRUE(all_finite(gpu)) << name_of(*ctx) << ", round " << round << ": unwritten (poisoned) texels remain";
      EXPECT_LT(reference::relative_l2(gpu, reference::bloom(input, bloom.config())), 1e-3)
          << name_of(*ctx) << ", round " << round;
      if (round > 0) reuses += reused(before, now);
      before = now;
    }
    std::printf("bloom, %s: %u view handles of destroyed views came back\n", name_of(*ctx).c_str(), reuses);
  }
}

// The blur's own bound on its error (BlurChoice::expected_relative_error, docs/BLUR.md).
TEST_F(CallerHandlesTest, GaussianBlurIsCorrectWithNewViewsOfDestroyedOnesHandles) {
  GaussianBlurConfig config;
  config.sigma_px = 2.5f;
  config.method = BlurMethod::separable;
  for (const Context* ctx : contexts()) {
    GaussianBlur blur(*ctx, config);
    std::vector<VkImageView> before, now;
    uint32_t reuses = 0;
    for (uint32_t round = 0; round < 3; ++round) {
      const CpuImage input = random_hdr(53, 41, 200 + round);
      const CpuImage gpu = run_once_with_new_images(
          *ctx, input, now, [&](VkCommandBuffer cmd, Image& in, Image& out) { blur.record(cmd, in, out); });
      ASSERT_TRUE(all_finite(gpu)) << name_of(*ctx) << ", round " << round << ": unwritten (poisoned) texels remain";
      EXPECT_LE(reference::rgba_relative_l2(gpu, reference::exact_gaussian(input, config.sigma_px)),
                blur.choice().expected_relative_error)
          << name_of(*ctx) << ", round " << round;
      if (round > 0) reuses += reused(before, now);
      before = now;
    }
    std::printf("gaussian blur, %s: %u view handles of destroyed views came back\n", name_of(*ctx).c_str(), reuses);
  }
}

// Buffers: on lavapipe the buffer case of the old per-handle caches happened to read the right
// numbers (the new buffers' memory came back at the old addresses too), while the image cases above
// crashed it; the property is the same, so it is checked the same way.
// New query and level buffers each round (the same sizes, so handles are likely reused);
// every level must equal the host's lod_level() to 1e-5 levels (the C++ twin's tolerance,
// docs/LOD.md and lod_test.cpp: both run lod_impl.h in fp32, differing by log2/sqrt rounding).
TEST_F(CallerHandlesTest, LodBatchIsCorrectWithNewBuffersOfDestroyedOnesHandles) {
  for (const Context* ctx : contexts()) {
    LodBatch batch(*ctx);
    const LodAtlasConfig atlas;
    const uint32_t n = 37;
    for (uint32_t round = 0; round < 3; ++round) {
      std::vector<LodQuery> queries(n);
      for (uint32_t i = 0; i < n; ++i) {
        LodQuery& q = queries[i];
        q.dudx = q.dvdy = 1.0f / float(1u << ((i + round) % 7));  // levels 0 to 6 on a 256-texel tile
        q.tex_w = q.tex_h = 256.0f;
        q.off_x = q.off_y = 512.0f;
      }
      const VkBufferUsageFlags usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
      detail::OwnedBuffer qbuf(*ctx, n * sizeof(LodQuery), usage, true);
      detail::OwnedBuffer lbuf(*ctx, n * sizeof(float), usage, true);
      std::memcpy(qbuf.mapped(), queries.data(), n * sizeof(LodQuery));
      qbuf.flush();
      std::vector<float> poison(n, std::numeric_limits<float>::quiet_NaN());
      std::memcpy(lbuf.mapped(), poison.data(), n * sizeof(float));
      lbuf.flush();
      Buffer qv{qbuf.buffer(), 0, qbuf.size(), usage};
      Buffer lv{lbuf.buffer(), 0, lbuf.size(), usage};
      ctx->run_once([&](VkCommandBuffer cmd) {
        batch.record(cmd, qv, lv, n, atlas);
        detail::Barriers b;
        b.use(lv, VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT);
        b.flush(cmd);
      });
      lbuf.invalidate();
      std::vector<float> levels(n);
      std::memcpy(levels.data(), lbuf.mapped(), n * sizeof(float));
      for (uint32_t i = 0; i < n; ++i) {
        EXPECT_NEAR(levels[i], lod_level(queries[i], atlas), 1e-5f)
            << name_of(*ctx) << ", round " << round << ", query " << i;
      }
    }
  }
}

// Hi-Z: a new depth image (R32F, sampled) each round, same size, so its view may get a destroyed
// one's handle; the pyramid (NaN-poisoned first) must equal the float64 reference bit for bit at
// every level, as in occlusion_test.cpp: each texel is the max (min when reversed) of exact inputs.
// 1030x771 builds 9 levels, so both dispatches (stream pass, tile pass from level 2) run.
TEST_F(CallerHandlesTest, HiZPyramidIsCorrectWithNewViewsOfDestroyedOnesHandles) {
  for (const Context* ctx : contexts()) {
    HiZConfig config;
    config.extent = {1030, 771};
    config.format = VK_FORMAT_R32_SFLOAT;
    HiZPyramid hiz(*ctx, config);
    const uint32_t levels = hiz.levels();
    ASSERT_GT(levels, 2u);
    std::vector<VkImageView> before, now;
    uint32_t reuses = 0;
    for (uint32_t round = 0; round < 3; ++round) {
      std::mt19937 rng(300 + round);
      std::uniform_real_distribution<float> unit(0.0f, 1.0f);
      reference::DepthImage depth{config.extent.width, config.extent.height,
                                  std::vector<float>(size_t(config.extent.width) * config.extent.height)};
      for (float& v : depth.depth) v = unit(rng);
      detail::OwnedImage img(*ctx, config.extent, config.format,
                             VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT);
      detail::upload_r32(*ctx, img.state, depth.depth);
      now = {img.state.view};
      ctx->run_once([&](VkCommandBuffer cmd) {
        detail::Barriers b;  // NaN in every level, so a level the pass did not write fails
        b.use(hiz.image(), VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_PIPELINE_STAGE_2_CLEAR_BIT,
              VK_ACCESS_2_TRANSFER_WRITE_BIT, levels);
        b.flush(cmd);
        VkClearColorValue nan{};
        for (float& c : nan.float32) c = std::nanf("");
        const VkImageSubresourceRange range{VK_IMAGE_ASPECT_COLOR_BIT, 0, levels, 0, 1};
        vkCmdClearColorImage(cmd, hiz.image().image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &nan, 1, &range);
        hiz.record(cmd, img.state);
      });
      const auto ref = reference::hiz_pyramid(depth, false, levels);
      for (uint32_t k = 1; k <= levels; ++k) {
        const VkExtent2D e{std::max(1u, config.extent.width >> k), std::max(1u, config.extent.height >> k)};
        const std::vector<float> gpu = detail::download_r32(*ctx, hiz.image(), k - 1, e, levels);
        ASSERT_EQ(gpu.size(), ref[k - 1].depth.size());
        size_t bad = 0;
        for (size_t i = 0; i < gpu.size(); ++i) bad += std::memcmp(&gpu[i], &ref[k - 1].depth[i], 4) != 0;
        EXPECT_EQ(bad, 0u) << name_of(*ctx) << ", round " << round << ", level " << k;
      }
      if (round > 0) reuses += reused(before, now);
      before = now;
    }
    std::printf("hi-z, %s: %u view handles of destroyed views came back\n", name_of(*ctx).c_str(), reuses);
  }
}

}  // namespace
}  // namespace glint::test
