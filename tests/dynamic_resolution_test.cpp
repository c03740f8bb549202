// Dynamic resolution: one effect object recorded at several sizes, in one command buffer and
// across frames in flight, with no resource destroyed while submitted work may still use it.
// Validation with synchronization validation is on (support/gpu_test.h fails a test on any
// message): freeing a pyramid that a pending command buffer uses is reported there, and usually
// crashes the driver as well.
#include <glint/bloom.h>
#include <glint/blur.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <mutex>
#include <string>
#include <vector>

#include "core/barriers.h"
#include "core/context_state.h"
#include "reference/bloom_reference.h"
#include "reference/blur_reference.h"
#include "support/effects.h"
#include "support/gpu_test.h"

namespace glint::test {
namespace {

constexpr VkFormat kF16 = VK_FORMAT_R16G16B16A16_SFLOAT;
constexpr VkFormat kF32 = VK_FORMAT_R32G32B32A32_SFLOAT;

// Tolerances, relative L2 against the float64 reference with fp32 intermediates and RGBA32F
// input and output: bloom 1e-3 (bloom_test.cpp: fp32 arithmetic lands far below), blur 1e-5
// (blur_test.cpp: fp32 sums of a few hundred products, 2^-24 each, with ~100x margin). An RGBA16F
// output adds one rounding of at most 2^-10 relative (truncation): 4e-3 as in blur_test.cpp.
constexpr double kBloomTol = 1e-3;
constexpr double kBlurTolFp32 = 1e-5;
constexpr double kBlurTolFp16 = 4e-3;

class DynamicResolutionTest : public GpuTest {};

blur_plan::Plan plan_of(const BlurChoice& c, float sigma_px) {
  blur_plan::Plan p;
  p.method =
      c.linear_sampling
          ? blur_plan::Method::separable_linear
          : static_cast<blur_plan::Method>(c.method == BlurMethod::separable ? 0u : static_cast<uint32_t>(c.method));
  p.sigma_px = sigma_px;
  p.radius = c.radius;
  p.levels = c.levels;
  p.level_sigma = c.level_sigma;
  p.dual_offset = c.dual_offset;
  return p;
}

// The float64 reference of what a GaussianBlur that chose `c` computes.
reference::DoubleImage gauss_reference(const BlurChoice& c, float sigma_px, const CpuImage& input) {
  const blur_plan::Plan p = plan_of(c, sigma_px);
  switch (c.method) {
    case BlurMethod::pyramid:
      return reference::gaussian_pyramid(input, p);
    case BlurMethod::dual:
      return reference::gaussian_dual(input, p);
    default:
      return c.linear_sampling ? reference::gaussian_separable_linear(input, sigma_px)
                               : reference::gaussian_separable(input, sigma_px);
  }
}

// ---- (a) several sizes in one command buffer, one submission ----

// A, B, then A again with another input: the second A finds its pyramid cached, B's pyramid is
// still used by the same command buffer. Each output against the float64 reference and, bit for
// bit, against a fresh Bloom that only ever saw that size (identical dispatches on identical data).
TEST_F(DynamicResolutionTest, BloomTwoSizesInOneCommandBuffer) {
  BloomConfig config;
  config.precision = Precision::fp32;
  config.iterations = 4;
  config.intensity = 0.8f;
  const VkExtent2D sizes[3] = {{97, 61}, {50, 31}, {97, 61}};
  std::vector<CpuImage> inputs;
  std::vector<detail::OwnedImage> in, out;
  std::vector<detail::OwnedBuffer> staging;
  for (int i = 0; i < 3; ++i) {
    inputs.push_back(random_hdr(sizes[i].width, sizes[i].height, 100 + i));
    in.push_back(make_image(inputs[i], kF32));
    out.push_back(make_poisoned(sizes[i], kF32));
    staging.push_back(detail::make_readback_staging(context(), out[i].state));
  }
  Bloom bloom(context(), config);
  context().run_once([&](VkCommandBuffer cmd) {
    for (int i = 0; i < 3; ++i) {
      bloom.record(cmd, in[i].state, out[i].state);
      detail::record_readback(cmd, out[i].state, staging[i]);
    }
  });
  for (int i = 0; i < 3; ++i) {
    SCOPED_TRACE(testing::Message() << "record " << i << ": " << sizes[i].width << "x" << sizes[i].height);
    const CpuImage got = detail::read_staged(staging[i], out[i].state);
    ASSERT_TRUE(all_finite(got)) << "unwritten (poisoned) texels remain";
    EXPECT_LT(reference::relative_l2(got, reference::bloom(inputs[i], config)), kBloomTol);
    EXPECT_TRUE(bit_equal(got, run_bloom_once(config, inputs[i], kF32)));
  }
}

// The pyramid hands its levels to the caller: after each record(), level(k) is the level of the
// size just recorded, read back in the same command buffer before the next size is recorded.
TEST_F(DynamicResolutionTest, BlurPyramidTwoSizesInOneCommandBuffer) {
  BlurPyramidConfig config;
  config.sigma_texels = {0.8f, 1.2f, 2.0f};
  config.precision = Precision::fp32;
  const VkExtent2D sizes[3] = {{97, 61}, {40, 70}, {97, 61}};
  std::vector<CpuImage> inputs;
  std::vector<detail::OwnedImage> in;
  std::vector<std::array<detail::OwnedBuffer, 3>> staging(3);
  std::vector<std::array<Image, 3>> level_images(3);
  for (int i = 0; i < 3; ++i) {
    inputs.push_back(random_hdr(sizes[i].width, sizes[i].height, 200 + i));
    in.push_back(make_image(inputs[i], kF32));
  }
  BlurPyramid pyramid(context(), config);
  context().run_once([&](VkCommandBuffer cmd) {
    for (int i = 0; i < 3; ++i) {
      pyramid.record(cmd, in[i].state);
      for (uint32_t k = 1; k <= 3; ++k) {
        staging[i][k - 1] = detail::make_readback_staging(context(), pyramid.level(k));
        detail::record_readback(cmd, pyramid.level(k), staging[i][k - 1]);
        level_images[i][k - 1] = pyramid.level(k);
      }
    }
  });
  for (int i = 0; i < 3; ++i) {
    const auto ref = reference::blur_pyramid(inputs[i], {0.8, 1.2, 2.0});
    for (int k = 0; k < 3; ++k) {
      SCOPED_TRACE(testing::Message() << "record " << i << " level " << k + 1);
      const CpuImage got = detail::read_staged(staging[i][k], level_images[i][k]);
      ASSERT_EQ(got.width, ref[k].width);
      ASSERT_EQ(got.height, ref[k].height);
      EXPECT_LT(reference::rgba_relative_l2(got, ref[k]), kBlurTolFp32);
    }
  }
}

// GaussianBlur caches per (size, output format): A to RGBA32F, B, A to RGBA16F, A to RGBA32F.
TEST_F(DynamicResolutionTest, GaussianBlurTwoSizesAndFormatsInOneCommandBuffer) {
  GaussianBlurConfig config;
  config.sigma_px = 3.0f;
  config.precision = Precision::fp32;
  struct Rec {
    VkExtent2D size;
    VkFormat format;
  };
  const Rec recs[4] = {{{97, 61}, kF32}, {{45, 52}, kF32}, {{97, 61}, kF16}, {{97, 61}, kF32}};
  std::vector<CpuImage> inputs;
  std::vector<detail::OwnedImage> in, out;
  std::vector<detail::OwnedBuffer> staging;
  std::vector<BlurChoice> choices(4);
  for (int i = 0; i < 4; ++i) {
    inputs.push_back(random_hdr(recs[i].size.width, recs[i].size.height, 300 + i));
    in.push_back(make_image(inputs[i], kF32));
    out.push_back(make_poisoned(recs[i].size, recs[i].format));
    staging.push_back(detail::make_readback_staging(context(), out[i].state));
  }
  GaussianBlur blur(context(), config);
  context().run_once([&](VkCommandBuffer cmd) {
    for (int i = 0; i < 4; ++i) {
      blur.record(cmd, in[i].state, out[i].state);
      choices[i] = blur.choice();
      detail::record_readback(cmd, out[i].state, staging[i]);
    }
  });
  for (int i = 0; i < 4; ++i) {
    SCOPED_TRACE(testing::Message() << "record " << i);
    const CpuImage got = detail::read_staged(staging[i], out[i].state);
    ASSERT_TRUE(all_finite(got));
    EXPECT_LT(reference::rgba_relative_l2(got, gauss_reference(choices[i], config.sigma_px, inputs[i])),
              recs[i].format == kF16 ? kBlurTolFp16 : kBlurTolFp32);
  }
}

// set_config() with a shape change while the command buffer still holds the old shape's pyramid:
// the old pyramid must survive until the submission is over.
TEST_F(DynamicResolutionTest, BloomShapeChangeInsideOneCommandBuffer) {
  BloomConfig a;
  a.precision = Precision::fp32;
  BloomConfig b = a;
  b.filter = BloomFilter::gauss9;
  b.iterations = 3;
  const CpuImage input = random_hdr(64, 48, 400);
  auto in = make_image(input, kF32);
  auto out_a = make_poisoned({64, 48}, kF32);
  auto out_b = make_poisoned({64, 48}, kF32);
  auto stage_a = detail::make_readback_staging(context(), out_a.state);
  auto stage_b = detail::make_readback_staging(context(), out_b.state);
  Bloom bloom(context(), a);
  context().run_once([&](VkCommandBuffer cmd) {
    bloom.record(cmd, in.state, out_a.state);
    detail::record_readback(cmd, out_a.state, stage_a);
    bloom.set_config(b);
    bloom.record(cmd, in.state, out_b.state);
    detail::record_readback(cmd, out_b.state, stage_b);
  });
  EXPECT_TRUE(bit_equal(detail::read_staged(stage_a, out_a.state), run_bloom_once(a, input, kF32)));
  EXPECT_TRUE(bit_equal(detail::read_staged(stage_b, out_b.state), run_bloom_once(b, input, kF32)));
  // Retired lazily: the old shape's pyramid goes at the next call that may retire.
  EXPECT_EQ(bloom.cached_sizes(), 2u);
  bloom.release_unused();
  EXPECT_EQ(bloom.cached_sizes(), 1u) << "the old shape's pyramid outlived its run_once()";
}

// ---- run_once() users: a size recorded only inside a completed run_once() is retired ----

TEST_F(DynamicResolutionTest, RunOnceKeepsOneSizeAndPrepareKeepsWhatItMade) {
  Bloom bloom(context());
  for (uint32_t i = 0; i < 6; ++i) {
    const VkExtent2D size{24 + 5 * i, 16 + 3 * i};
    auto in = make_poisoned(size, kF16);
    auto out = make_poisoned(size, kF16);
    context().run_once([&](VkCommandBuffer cmd) { bloom.record(cmd, in.state, out.state); });
    EXPECT_EQ(bloom.cached_sizes(), 1u) << "size " << i;
  }
  // Prepared sizes are kept for frames_in_flight frames (an engine warming several sizes up).
  GaussianBlur blur(context());
  blur.prepare({40, 30});
  blur.prepare({80, 60});
  EXPECT_EQ(blur.cached_sizes(), 2u);
  const uint64_t objects = context().objects_created();
  blur.prepare({40, 30});
  EXPECT_EQ(context().objects_created(), objects) << "a prepared size was made again";
  blur.release_unused();  // nothing recorded them: both safe, the current one is kept
  EXPECT_EQ(blur.cached_sizes(), 1u);
}

// ---- (b) a size change every frame with frames in flight ----

// The caller's side of a frame loop: frames_in_flight command buffers and fences on the test
// context's queue.
class Frames {
 public:
  explicit Frames(uint32_t n) : n_(n), cmds_(n), fences_(n) {
    const VkDevice dev = context().device();
    VkCommandPoolCreateInfo pool{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    pool.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    pool.queueFamilyIndex = context().queue_family_index();
    EXPECT_EQ(vkCreateCommandPool(dev, &pool, nullptr, &pool_), VK_SUCCESS);
    VkCommandBufferAllocateInfo alloc{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    alloc.commandPool = pool_;
    alloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    alloc.commandBufferCount = n;
    EXPECT_EQ(vkAllocateCommandBuffers(dev, &alloc, cmds_.data()), VK_SUCCESS);
    VkFenceCreateInfo fence{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    fence.flags = VK_FENCE_CREATE_SIGNALED_BIT;
    for (VkFence& f : fences_) EXPECT_EQ(vkCreateFence(dev, &fence, nullptr, &f), VK_SUCCESS);
  }
  ~Frames() {
    wait_all();
    for (VkFence f : fences_) vkDestroyFence(context().device(), f, nullptr);
    vkDestroyCommandPool(context().device(), pool_, nullptr);
  }
  Frames(const Frames&) = delete;
  Frames& operator=(const Frames&) = delete;

  /// Waits for the slot's previous frame, then starts recording the slot's command buffer.
  VkCommandBuffer begin(uint32_t slot) {
    wait(slot);
    EXPECT_EQ(vkResetFences(context().device(), 1, &fences_[slot]), VK_SUCCESS);
    EXPECT_EQ(vkResetCommandBuffer(cmds_[slot], 0), VK_SUCCESS);
    VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    EXPECT_EQ(vkBeginCommandBuffer(cmds_[slot], &begin), VK_SUCCESS);
    return cmds_[slot];
  }
  void submit(uint32_t slot) {
    EXPECT_EQ(vkEndCommandBuffer(cmds_[slot]), VK_SUCCESS);
    VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    submit.commandBufferCount = 1;
    submit.pCommandBuffers = &cmds_[slot];
    std::lock_guard<std::recursive_mutex> lock(context().state().submit_mutex);
    EXPECT_EQ(vkQueueSubmit(context().state().queue, 1, &submit, fences_[slot]), VK_SUCCESS);
  }
  void wait(uint32_t slot) {
    EXPECT_EQ(vkWaitForFences(context().device(), 1, &fences_[slot], VK_TRUE, UINT64_MAX), VK_SUCCESS);
  }
  void wait_all() {
    for (uint32_t i = 0; i < n_; ++i) wait(i);
  }

 private:
  uint32_t n_;
  VkCommandPool pool_ = VK_NULL_HANDLE;
  std::vector<VkCommandBuffer> cmds_;
  std::vector<VkFence> fences_;
};

// Level k of a BlurPyramid of `input` (docs/BLUR.md: half size per level, floor, at least 1).
VkExtent2D pyramid_level_extent(VkExtent2D input, uint32_t k) {
  for (uint32_t i = 0; i < k; ++i) input = {std::max(1u, input.width / 2), std::max(1u, input.height / 2)};
  return input;
}

// 100 frames, 3 in flight, the size changes every frame: first cycling through 7 sizes (a size
// comes back after it was retired), then alternating two (both stay cached: nothing is made),
// then cycling again. Bloom, BlurPyramid and GaussianBlur are recorded into every frame (and the
// pyramid asked to release_unused() after each); every
// frame's outputs are read back when its fence is waited for and compared bit for bit with a fresh
// effect that only ever saw that size; the number of cached sizes never exceeds frames_in_flight.
TEST_F(DynamicResolutionTest, SizeChangesEveryFrameWithFramesInFlight) {
  const uint32_t n = context().frames_in_flight();
  ASSERT_EQ(n, 3u) << "the test context keeps the default of ContextOptions::frames_in_flight";
  const std::vector<VkExtent2D> sizes = {{64, 40}, {33, 47}, {48, 48}, {71, 29}, {20, 12}, {57, 61}, {40, 64}};
  const auto size_of_frame = [](uint32_t f) -> uint32_t {
    if (f < 40) return (3 * f) % 7;
    if (f < 70) return f % 2 ? 1 : 2;
    return (5 * f) % 7;
  };
  constexpr uint32_t kFrames = 100;

  BloomConfig bloom_config;
  bloom_config.precision = Precision::fp32;
  GaussianBlurConfig gauss_config;
  gauss_config.sigma_px = 2.5f;
  gauss_config.precision = Precision::fp32;
  BlurPyramidConfig pyramid_config;
  pyramid_config.precision = Precision::fp32;

  // Inputs and the expected outputs of a fresh effect per size.
  std::vector<CpuImage> inputs;
  std::vector<detail::OwnedImage> in;
  std::vector<CpuImage> want_bloom, want_gauss;
  std::vector<std::array<CpuImage, 3>> want_levels;
  for (size_t i = 0; i < sizes.size(); ++i) {
    inputs.push_back(random_hdr(sizes[i].width, sizes[i].height, 500 + static_cast<uint32_t>(i)));
    in.push_back(make_image(inputs[i], kF32));
    want_bloom.push_back(run_bloom_once(bloom_config, inputs[i], kF32));
    auto gin = make_image(inputs[i], kF32);
    auto gout = make_poisoned(sizes[i], kF32);
    GaussianBlur g(context(), gauss_config);
    BlurPyramid p(context(), pyramid_config);
    context().run_once([&](VkCommandBuffer cmd) {
      g.record(cmd, gin.state, gout.state);
      p.record(cmd, gin.state);
    });
    want_gauss.push_back(detail::download(context(), gout.state));
    want_levels.push_back({detail::download(context(), p.level(1)), detail::download(context(), p.level(2)),
                           detail::download(context(), p.level(3))});
  }

  // Per frame slot and size: outputs and staging buffers (made before the loop).
  struct Slot {
    std::vector<detail::OwnedImage> bloom_out, gauss_out;
    std::vector<detail::OwnedBuffer> bloom_stage, gauss_stage;
    std::vector<std::array<detail::OwnedBuffer, 3>> level_stage;
    std::vector<std::array<Image, 3>> level_image;  // extent and format for read_staged
    int frame = -1;                                 // the frame last submitted in this slot
  };
  std::vector<Slot> slots(n);
  for (Slot& s : slots) {
    for (size_t i = 0; i < sizes.size(); ++i) {
      s.bloom_out.push_back(make_poisoned(sizes[i], kF32));
      s.gauss_out.push_back(make_poisoned(sizes[i], kF32));
      s.bloom_stage.push_back(detail::make_readback_staging(context(), s.bloom_out.back().state));
      s.gauss_stage.push_back(detail::make_readback_staging(context(), s.gauss_out.back().state));
      std::array<Image, 3> levels;
      std::array<detail::OwnedBuffer, 3> stages;
      for (uint32_t k = 0; k < 3; ++k) {
        levels[k].extent = pyramid_level_extent(sizes[i], k + 1);
        levels[k].format = kF32;
        stages[k] = detail::make_readback_staging(context(), levels[k]);
      }
      s.level_image.push_back(levels);
      s.level_stage.push_back(std::move(stages));
    }
  }

  Bloom bloom(context(), bloom_config);
  GaussianBlur gauss(context(), gauss_config);
  BlurPyramid pyramid(context(), pyramid_config);
  uint32_t frames_checked = 0;
  const auto check = [&](Slot& s) {
    if (s.frame < 0) return;
    const uint32_t i = size_of_frame(static_cast<uint32_t>(s.frame));
    SCOPED_TRACE(testing::Message() << "frame " << s.frame << ", size " << sizes[i].width << "x" << sizes[i].height);
    EXPECT_TRUE(bit_equal(detail::read_staged(s.bloom_stage[i], s.bloom_out[i].state), want_bloom[i])) << "bloom";
    EXPECT_TRUE(bit_equal(detail::read_staged(s.gauss_stage[i], s.gauss_out[i].state), want_gauss[i])) << "gauss";
    for (uint32_t k = 0; k < 3; ++k) {
      EXPECT_TRUE(bit_equal(detail::read_staged(s.level_stage[i][k], s.level_image[i][k]), want_levels[i][k]))
          << "pyramid level " << k + 1;
    }
    ++frames_checked;
  };

  Frames frames(n);
  uint64_t objects_at_46 = 0;
  for (uint32_t f = 0; f < kFrames; ++f) {
    const uint32_t slot = f % n;
    const uint32_t i = size_of_frame(f);
    if (f == 46) objects_at_46 = context().objects_created();
    VkCommandBuffer cmd = frames.begin(slot);  // waits for frame f - n
    check(slots[slot]);
    context().begin_frame();
    Slot& s = slots[slot];
    detail::record_fill(cmd, s.bloom_out[i].state, std::nanf(""));
    detail::record_fill(cmd, s.gauss_out[i].state, std::nanf(""));
    bloom.record(cmd, in[i].state, s.bloom_out[i].state);
    gauss.record(cmd, in[i].state, s.gauss_out[i].state);
    pyramid.record(cmd, in[i].state);
    detail::record_readback(cmd, s.bloom_out[i].state, s.bloom_stage[i]);
    detail::record_readback(cmd, s.gauss_out[i].state, s.gauss_stage[i]);
    for (uint32_t k = 0; k < 3; ++k) {
      ASSERT_EQ(pyramid.level(k + 1).extent.width, s.level_image[i][k].extent.width);
      ASSERT_EQ(pyramid.level(k + 1).extent.height, s.level_image[i][k].extent.height);
      detail::record_readback(cmd, pyramid.level(k + 1), s.level_stage[i][k]);
    }
    frames.submit(slot);
    s.frame = static_cast<int>(f);
    // release_unused() may destroy only what frames f - n and earlier used.
    pyramid.release_unused();
    EXPECT_LE(bloom.cached_sizes(), n) << "frame " << f;
    EXPECT_LE(gauss.cached_sizes(), n) << "frame " << f;
    EXPECT_LE(pyramid.cached_sizes(), n) << "frame " << f;
    if (f == 69) {
      EXPECT_EQ(context().objects_created(), objects_at_46) << "alternating two cached sizes made objects";
    }
  }
  frames.wait_all();
  for (Slot& s : slots) check(s);
  EXPECT_EQ(frames_checked, kFrames);

  // The caller knows the device is idle: every size but the current one goes.
  context().mark_idle();
  bloom.release_unused();
  gauss.release_unused();
  pyramid.release_unused();
  EXPECT_EQ(bloom.cached_sizes(), 1u);
  EXPECT_EQ(gauss.cached_sizes(), 1u);
  EXPECT_EQ(pyramid.cached_sizes(), 1u);
}

// Without begin_frame() nothing recorded into the caller's command buffers is known to be done:
// the effect keeps kMaxCachedSizes sizes, then refuses a new one before recording anything,
// naming what to call. mark_idle() after waiting lets the sizes go.
TEST_F(DynamicResolutionTest, WithoutBeginFrameAFullCacheRefusesANewSize) {
  Bloom bloom(context());
  std::vector<detail::OwnedImage> in, out;
  for (uint32_t i = 0; i <= kMaxCachedSizes + 1; ++i) {
    in.push_back(make_poisoned({8 + i, 8}, kF16));
    out.push_back(make_poisoned({8 + i, 8}, kF16));
  }
  Frames frames(1);
  VkCommandBuffer cmd = frames.begin(0);
  for (uint32_t i = 0; i < kMaxCachedSizes; ++i) bloom.record(cmd, in[i].state, out[i].state);
  EXPECT_EQ(bloom.cached_sizes(), kMaxCachedSizes);
  const uint64_t commands = detail::recorded_commands();
  try {
    bloom.record(cmd, in[kMaxCachedSizes].state, out[kMaxCachedSizes].state);
    ADD_FAILURE() << "a new size was accepted while every cached size may be in flight";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::invalid_argument);
    EXPECT_NE(std::string(e.what()).find("begin_frame"), std::string::npos) << e.what();
  }
  EXPECT_EQ(detail::recorded_commands(), commands) << "the refused record() recorded a command";
  EXPECT_EQ(bloom.cached_sizes(), kMaxCachedSizes);
  frames.submit(0);
  frames.wait(0);
  context().mark_idle();
  cmd = frames.begin(0);
  bloom.record(cmd, in[kMaxCachedSizes + 1].state, out[kMaxCachedSizes + 1].state);
  EXPECT_EQ(bloom.cached_sizes(), 1u) << "after mark_idle() the unused sizes are retired";
  frames.submit(0);
}

TEST_F(DynamicResolutionTest, FramesInFlightIsChecked) {
  for (uint32_t bad : {0u, 17u}) {
    ContextOptions options;
    options.frames_in_flight = bad;
    try {
      Context::create(options);
      ADD_FAILURE() << "frames_in_flight " << bad << " accepted";
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::invalid_argument);
      EXPECT_NE(std::string(e.what()).find("ContextOptions::frames_in_flight"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("1 to 16"), std::string::npos) << e.what();
    }
    AdoptInfo adopt = adopt_info_of_context();
    adopt.frames_in_flight = bad;
    try {
      Context::adopt(adopt);
      ADD_FAILURE() << "AdoptInfo::frames_in_flight " << bad << " accepted";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("AdoptInfo::frames_in_flight"), std::string::npos) << e.what();
    }
  }
  AdoptInfo adopt = adopt_info_of_context();
  adopt.frames_in_flight = 16;
  Context adopted = Context::adopt(with_glint_extensions(adopt));
  EXPECT_EQ(adopted.frames_in_flight(), 16u);
  EXPECT_EQ(adopted.frame(), 0u);
  EXPECT_EQ(adopted.begin_frame(), 1u);
  adopted.mark_idle();
  EXPECT_EQ(adopted.frame(), 17u);
  EXPECT_THROW(adopted.wait_idle(), Error);
}

}  // namespace
}  // namespace glint::test
