// Effects keep nothing that names the caller's views or buffers: descriptors are pushed with each
// dispatch (VK_KHR_push_descriptor). Vulkan may give a new object the handle of a destroyed one
// (lavapipe usually does for an object of the same size); an effect that cached descriptor sets by
// handle would bind the destroyed object's descriptors to the new one, which synchronization and
// core validation report and which writes the old image's memory, leaving the new output
// poisoned. Each test records, destroys the caller's objects, makes new ones with other contents,
// records again with no call in between and compares with the float64 reference. Validation is on
// (support/gpu_test.h fails a test on any message).
#include <glint/bloom.h>
#include <glint/blur.h>
#include <glint/lod.h>

#include <cstring>
#include <limits>
#include <vector>

#include "core/barriers.h"
#include "reference/bloom_reference.h"
#include "reference/blur_reference.h"
#include "support/gpu_test.h"

namespace glint::test {
namespace {

constexpr VkFormat kF32 = VK_FORMAT_R32G32B32A32_SFLOAT;

class CallerHandlesTest : public GpuTest {};

// Runs `record` on a new input made from `pixels` into a new NaN-poisoned output, reads the output
// back and destroys both; `handles` gets the two views' handles.
template <typename Record>
CpuImage run_once_with_new_images(const CpuImage& pixels, std::vector<VkImageView>& handles, Record&& record) {
  auto in = make_image(pixels, kF32);
  auto out = make_poisoned({pixels.width, pixels.height}, kF32);
  handles = {in.state.view, out.state.view};
  context().run_once([&](VkCommandBuffer cmd) { record(cmd, in.state, out.state); });
  return detail::download(context(), out.state);
}

// fp32 input, levels and output: relative L2 within 1e-3 of the reference (the bloom tests'
// fp32 tolerance, bloom_test.cpp).
TEST_F(CallerHandlesTest, BloomIsCorrectWithNewViewsOfDestroyedOnesHandles) {
  Bloom bloom(context());
  std::vector<VkImageView> first, second;
  uint32_t reused = 0;
  for (uint32_t round = 0; round < 4; ++round) {
    const CpuImage input = random_hdr(61, 37, 100 + round);
    const CpuImage gpu =
        run_once_with_new_images(input, round == 0 ? first : second,
                                 [&](VkCommandBuffer cmd, Image& in, Image& out) { bloom.record(cmd, in, out); });
    ASSERT_TRUE(all_finite(gpu)) << "round " << round << ": unwritten (poisoned) texels remain";
    EXPECT_LT(reference::relative_l2(gpu, reference::bloom(input, bloom.config())), 1e-3) << "round " << round;
    if (round > 0)
      reused += (second[0] == first[0] || second[0] == first[1] || second[1] == first[0] || second[1] == first[1]);
  }
  RecordProperty("rounds_with_a_reused_view_handle", static_cast<int>(reused));
}

// The blur's own bound on its error (BlurChoice::expected_relative_error, docs/BLUR.md).
TEST_F(CallerHandlesTest, GaussianBlurIsCorrectWithNewViewsOfDestroyedOnesHandles) {
  GaussianBlurConfig config;
  config.sigma_px = 2.5f;
  config.method = BlurMethod::separable;
  GaussianBlur blur(context(), config);
  std::vector<VkImageView> handles;
  for (uint32_t round = 0; round < 3; ++round) {
    const CpuImage input = random_hdr(53, 41, 200 + round);
    const CpuImage gpu = run_once_with_new_images(
        input, handles, [&](VkCommandBuffer cmd, Image& in, Image& out) { blur.record(cmd, in, out); });
    ASSERT_TRUE(all_finite(gpu)) << "round " << round << ": unwritten (poisoned) texels remain";
    EXPECT_LE(reference::rgba_relative_l2(gpu, reference::exact_gaussian(input, config.sigma_px)),
              blur.choice().expected_relative_error)
        << "round " << round;
  }
}

// Buffers: new query and level buffers each round (the same sizes, so handles are likely reused);
// every level must equal the host's lod_level() to 1e-5 levels (the C++ twin's tolerance,
// docs/LOD.md and lod_test.cpp: both run lod_impl.h in fp32, differing by log2/sqrt rounding).
TEST_F(CallerHandlesTest, LodBatchIsCorrectWithNewBuffersOfDestroyedOnesHandles) {
  LodBatch batch(context());
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
    detail::OwnedBuffer qbuf(context(), n * sizeof(LodQuery), usage, true);
    detail::OwnedBuffer lbuf(context(), n * sizeof(float), usage, true);
    std::memcpy(qbuf.mapped(), queries.data(), n * sizeof(LodQuery));
    qbuf.flush();
    std::vector<float> poison(n, std::numeric_limits<float>::quiet_NaN());
    std::memcpy(lbuf.mapped(), poison.data(), n * sizeof(float));
    lbuf.flush();
    Buffer qv{qbuf.buffer(), 0, qbuf.size(), usage};
    Buffer lv{lbuf.buffer(), 0, lbuf.size(), usage};
    context().run_once([&](VkCommandBuffer cmd) {
      batch.record(cmd, qv, lv, n, atlas);
      detail::Barriers b;
      b.use(lv, VK_PIPELINE_STAGE_2_HOST_BIT, VK_ACCESS_2_HOST_READ_BIT);
      b.flush(cmd);
    });
    lbuf.invalidate();
    std::vector<float> levels(n);
    std::memcpy(levels.data(), lbuf.mapped(), n * sizeof(float));
    for (uint32_t i = 0; i < n; ++i) {
      EXPECT_NEAR(levels[i], lod_level(queries[i], atlas), 1e-5f) << "round " << round << ", query " << i;
    }
  }
}

}  // namespace
}  // namespace glint::test
