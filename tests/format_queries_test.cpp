// The format features of a context are read from the device once, when the context is made
// (core/formats.h): effects' constructors and record() read the table and never call
// vkGetPhysicalDeviceFormatProperties*. This program interposes those entry points (a definition
// in the executable takes precedence over the Vulkan loader's for glint's calls, which go through
// the loader's exported symbols) and counts the calls, forwarding each to the loader.
#include <dlfcn.h>
#include <glint/bloom.h>
#include <glint/blur.h>
#include <glint/flare.h>
#include <glint/occlusion.h>

#include <atomic>
#include <cstring>

#include "core/check.h"
#include "core/formats.h"
#include "reference/occlusion_reference.h"
#include "support/flare_scene.h"
#include "support/gpu_test.h"

namespace {

std::atomic<uint64_t> g_format_queries{0};

template <typename F>
F next_symbol(const char* name) {
  void* f = dlsym(RTLD_NEXT, name);
  if (!f) std::abort();  // the loader always exports the Vulkan 1.0 and 1.1 entry points
  return reinterpret_cast<F>(f);
}

}  // namespace

extern "C" {

VKAPI_ATTR void VKAPI_CALL vkGetPhysicalDeviceFormatProperties(VkPhysicalDevice physical_device, VkFormat format,
                                                               VkFormatProperties* properties) {
  static const auto next = next_symbol<PFN_vkGetPhysicalDeviceFormatProperties>("vkGetPhysicalDeviceFormatProperties");
  ++g_format_queries;
  next(physical_device, format, properties);
}

VKAPI_ATTR void VKAPI_CALL vkGetPhysicalDeviceFormatProperties2(VkPhysicalDevice physical_device, VkFormat format,
                                                                VkFormatProperties2* properties) {
  static const auto next =
      next_symbol<PFN_vkGetPhysicalDeviceFormatProperties2>("vkGetPhysicalDeviceFormatProperties2");
  ++g_format_queries;
  next(physical_device, format, properties);
}

}  // extern "C"

namespace glint::test {
namespace {

class FormatQueriesTest : public GpuTest {};

// The hook sees glint's queries: adopting a device reads every format of the table, once each. (If
// it did not, the test below could not fail.)
TEST_F(FormatQueriesTest, AdoptionReadsEveryCheckedFormatOnce) {
  const AdoptInfo info = with_glint_extensions(adopt_info_of_context());  // context() is made by now
  const uint64_t before = g_format_queries.load();
  const Context adopted = Context::adopt(info);
  EXPECT_EQ(g_format_queries.load() - before, detail::kCheckedFormats.size());
}

// The table holds what the device reports, format by format.
TEST_F(FormatQueriesTest, TheTableMatchesTheDevice) {
  for (VkFormat f : detail::kCheckedFormats) {
    VkFormatProperties3 p3{VK_STRUCTURE_TYPE_FORMAT_PROPERTIES_3};
    VkFormatProperties2 p2{VK_STRUCTURE_TYPE_FORMAT_PROPERTIES_2, &p3};
    vkGetPhysicalDeviceFormatProperties2(context().physical_device(), f, &p2);
    EXPECT_EQ(detail::format_features(context(), f), p3.optimalTilingFeatures) << detail::format_name(f);
  }
  try {
    detail::format_features(context(), VK_FORMAT_R8G8B8A8_UNORM);
    FAIL() << "a format outside the table was answered";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::unsupported_format);
    EXPECT_NE(std::string(e.what()).find("VK_FORMAT_R8G8B8A8_UNORM"), std::string::npos) << e.what();
  }
}

// Making effects and recording frames with them, each effect's first record() included, queries
// no format property: every check reads the context's table.
TEST_F(FormatQueriesTest, EffectsAndRecordNeverQueryTheDevice) {
  const Context& ctx = context();
  const VkExtent2D extent{48, 32};
  auto input = make_image(random_hdr(extent.width, extent.height, 1), VK_FORMAT_R16G16B16A16_SFLOAT);
  auto bloom_out = make_poisoned(extent, VK_FORMAT_R16G16B16A16_SFLOAT);
  auto blur_out = make_poisoned(extent, VK_FORMAT_R32G32B32A32_SFLOAT);
  reference::DepthImage depth{extent.width, extent.height, std::vector<float>(size_t(extent.width) * extent.height)};
  for (size_t i = 0; i < depth.depth.size(); ++i) depth.depth[i] = float(i % 97) / 97.0f;
  auto depth_image = make_depth(depth, VK_FORMAT_D32_SFLOAT);

  const uint64_t before = g_format_queries.load();
  Bloom bloom(ctx, BloomConfig{});
  GaussianBlurConfig blur_config;
  blur_config.method = BlurMethod::separable;
  blur_config.linear_sampling = true;  // record() also checks the input's linear filtering
  GaussianBlur blur(ctx, blur_config);
  HiZConfig hiz_config;
  hiz_config.extent = extent;
  hiz_config.format = VK_FORMAT_D32_SFLOAT;
  HiZPyramid hiz(ctx, hiz_config);
  LensFlare flare(ctx, VK_FORMAT_R16G16B16A16_SFLOAT, extent);
  for (int frame = 0; frame < 3; ++frame) {
    ctx.run_once([&](VkCommandBuffer cmd) {
      bloom.record(cmd, input.state, bloom_out.state);
      blur.record(cmd, input.state, blur_out.state);
      hiz.record(cmd, depth_image.state);
    });
  }
  EXPECT_EQ(g_format_queries.load(), before);
}

}  // namespace
}  // namespace glint::test
