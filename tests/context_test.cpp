// Context: device listing and selection, the adopted path (an engine's own device and command
// buffer), and proof that the validation layer is really listening.
#include <glint/bloom.h>

#include <cstdlib>
#include <cstring>
#include <vector>

#include "core/context_state.h"
#include "core/pipeline.h"
#include "core/resources.h"
#include "demo/demo_scene.h"
#include "reference/bloom_reference.h"
#include "support/environment.h"
#include "support/gpu_test.h"
#include "support/transfer.h"

namespace glint::test {
namespace {

class ContextTest : public GpuTest {};

TEST_F(ContextTest, ListsDevicesAndSelectsByNameAndIndex) {
  const auto devices = list_devices();
  ASSERT_FALSE(devices.empty());
  ContextOptions by_index;
  by_index.device = "0";
  EXPECT_EQ(Context::create(by_index).info().name, devices[0].name);
  ContextOptions by_name;
  by_name.device = devices[0].name.substr(0, 4);
  EXPECT_EQ(Context::create(by_name).info().name.substr(0, 4), devices[0].name.substr(0, 4));
}

TEST_F(ContextTest, UnknownDeviceIsAClearError) {
  ContextOptions options;
  options.device = "no-such-gpu-xyz";
  try {
    Context::create(options);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::no_device);
    EXPECT_NE(std::string(e.what()).find("no-such-gpu-xyz"), std::string::npos);
  }
  options.device = "99";
  EXPECT_THROW(Context::create(options), Error);
}

// ContextOptions::workgroup_2d replaces every image kernel's workgroup choice; out-of-range values
// are refused naming the field and the device's limit.
TEST_F(ContextTest, WorkgroupOverrideIsCheckedAndUsed) {
  ContextOptions options;
  options.workgroup_2d = {8, 4};
  const Context forced = Context::create(options);
  const detail::Workgroup2D g = detail::choose_workgroup_2d(forced);
  EXPECT_EQ(g.x, 8u);
  EXPECT_EQ(g.y, 4u);
  for (VkExtent2D bad : {VkExtent2D{0, 8}, VkExtent2D{8, 0}, VkExtent2D{4096, 4096}}) {
    options.workgroup_2d = bad;
    try {
      Context::create(options);
      ADD_FAILURE() << bad.width << "x" << bad.height << ": no error";
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::invalid_argument);
      EXPECT_NE(std::string(e.what()).find("ContextOptions::workgroup_2d = " + std::to_string(bad.width) + "x" +
                                           std::to_string(bad.height)),
                std::string::npos)
          << e.what();
      EXPECT_NE(std::string(e.what()).find("maxComputeWorkGroupInvocations"), std::string::npos) << e.what();
    }
  }
  ContextOptions gpu_av_alone;
  gpu_av_alone.gpu_assisted_validation = true;
  EXPECT_THROW(Context::create(gpu_av_alone), Error);
}

// The tools' environment mapping: GLINT_* variables become ContextOptions fields, malformed values
// are errors naming the variable (the library itself reads none: ctest's consumer_check looks for
// getenv in the installed library).
TEST(ContextEnvironment, ToolsMapGlintVariablesToOptions) {
  struct Restore {
    ~Restore() {
      unsetenv("GLINT_WORKGROUP");
      unsetenv("GLINT_GPU_AV");
    }
  } restore;
  setenv("GLINT_WORKGROUP", "16x4", 1);
  ContextOptions o = tools::context_options_from_environment();
  EXPECT_EQ(o.workgroup_2d.width, 16u);
  EXPECT_EQ(o.workgroup_2d.height, 4u);
  for (const char* bad : {"16by8", "16x", "0x8", "16x8x2"}) {
    setenv("GLINT_WORKGROUP", bad, 1);
    try {
      tools::context_options_from_environment();
      ADD_FAILURE() << bad << ": no error";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("GLINT_WORKGROUP"), std::string::npos) << e.what();
    }
  }
  unsetenv("GLINT_WORKGROUP");
  setenv("GLINT_GPU_AV", "yes", 1);
  EXPECT_THROW(tools::context_options_from_environment(), Error);
  setenv("GLINT_GPU_AV", "1", 1);
  o = tools::context_options_from_environment();
  EXPECT_TRUE(o.gpu_assisted_validation && o.validation);
  ContextOptions named;
  named.device = "by-flag";
  setenv("GLINT_DEVICE", "by-env", 1);
  EXPECT_EQ(tools::context_options_from_environment(named).device, "by-flag");
  unsetenv("GLINT_DEVICE");
}

// The validation layer reports a deliberately invalid call: without this, "no messages" could
// mean "no layer". The messages it provokes are expected, so the fixture's count is reset.
TEST(ContextValidation, ValidationLayerCatchesAnInvalidCall) {
  const Context& ctx = context();
  const uint32_t before = ctx.validation_messages();
  VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  info.size = 0;  // VUID-VkBufferCreateInfo-size-00912: size must be greater than 0
  info.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
  VkBuffer buffer = VK_NULL_HANDLE;
  VkResult r = vkCreateBuffer(ctx.device(), &info, nullptr, &buffer);
  if (r == VK_SUCCESS && buffer) vkDestroyBuffer(ctx.device(), buffer, nullptr);
  EXPECT_GT(ctx.validation_messages(), before);
}

// An engine creates its own instance, device, pool and command buffer; glint adopts them, records
// bloom, and the engine submits. glint must submit nothing itself.
TEST_F(ContextTest, AdoptedDeviceRunsBloomInTheEnginesCommandBuffer) {
  const Context& mine = context();  // borrow its instance and physical device, make a new device
  const uint32_t family = mine.queue_family_index();
  VkPhysicalDeviceVulkan13Features f13{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES};
  f13.synchronization2 = VK_TRUE;
  f13.maintenance4 = VK_TRUE;  // glint kernels take their workgroup size from specialization (LocalSizeId)
  float priority = 1.0f;
  VkDeviceQueueCreateInfo q{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
  q.queueFamilyIndex = family;
  q.queueCount = 1;
  q.pQueuePriorities = &priority;
  VkDeviceCreateInfo di{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
  di.pNext = &f13;
  di.queueCreateInfoCount = 1;
  di.pQueueCreateInfos = &q;
  di.enabledExtensionCount = kGlintDeviceExtensionCount;
  di.ppEnabledExtensionNames = kGlintDeviceExtensions;
  VkDevice device = VK_NULL_HANDLE;
  ASSERT_EQ(vkCreateDevice(mine.physical_device(), &di, nullptr, &device), VK_SUCCESS);
  VkQueue queue;
  vkGetDeviceQueue(device, family, 0, &queue);
  VkCommandPoolCreateInfo pi{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  pi.queueFamilyIndex = family;
  VkCommandPool pool;
  ASSERT_EQ(vkCreateCommandPool(device, &pi, nullptr, &pool), VK_SUCCESS);
  {
    Context engine = Context::adopt(
        with_glint_extensions({mine.instance(), VK_API_VERSION_1_3, mine.physical_device(), device, family, &f13}));
    EXPECT_TRUE(engine.is_adopted());
    EXPECT_THROW(engine.run_once([](VkCommandBuffer) {}), Error);

    // Images live on the engine's device; uploads go through a staging buffer we copy ourselves.
    const CpuImage input = random_hdr(48, 32, 17);
    detail::OwnedImage in(engine, {48, 32}, VK_FORMAT_R32G32B32A32_SFLOAT, detail::kToolImageUsage);
    detail::OwnedImage out(engine, {48, 32}, VK_FORMAT_R32G32B32A32_SFLOAT, detail::kToolImageUsage);
    detail::OwnedBuffer up(engine, input.rgba.size() * 4, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, true);
    detail::OwnedBuffer down(engine, input.rgba.size() * 4, VK_BUFFER_USAGE_TRANSFER_DST_BIT, true);
    std::memcpy(up.mapped(), input.rgba.data(), input.rgba.size() * 4);
    up.flush();

    Bloom bloom(engine);
    VkCommandBufferAllocateInfo ai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    ai.commandPool = pool;
    ai.commandBufferCount = 1;
    VkCommandBuffer cmd;
    ASSERT_EQ(vkAllocateCommandBuffers(device, &ai, &cmd), VK_SUCCESS);
    VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    vkBeginCommandBuffer(cmd, &bi);
    VkBufferImageCopy region{};
    region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    region.imageExtent = {48, 32, 1};
    VkImageMemoryBarrier2 to_dst{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2};
    to_dst.dstStageMask = VK_PIPELINE_STAGE_2_COPY_BIT;
    to_dst.dstAccessMask = VK_ACCESS_2_TRANSFER_WRITE_BIT;
    to_dst.newLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
    to_dst.image = in.state.image;
    to_dst.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    VkDependencyInfo dep{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
    dep.imageMemoryBarrierCount = 1;
    dep.pImageMemoryBarriers = &to_dst;
    vkCmdPipelineBarrier2(cmd, &dep);
    vkCmdCopyBufferToImage(cmd, up.buffer(), in.state.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
    // Tell glint how the engine last used the images.
    in.state.layout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
    in.state.stage = VK_PIPELINE_STAGE_2_COPY_BIT;
    in.state.access = VK_ACCESS_2_TRANSFER_WRITE_BIT;
    bloom.record(cmd, in.state, out.state);
    // glint documents the output's state after record(): GENERAL, written by compute.
    EXPECT_EQ(out.state.layout, VK_IMAGE_LAYOUT_GENERAL);
    VkImageMemoryBarrier2 to_src{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2};
    to_src.srcStageMask = out.state.stage;
    to_src.srcAccessMask = out.state.access;
    to_src.dstStageMask = VK_PIPELINE_STAGE_2_COPY_BIT;
    to_src.dstAccessMask = VK_ACCESS_2_TRANSFER_READ_BIT;
    to_src.oldLayout = out.state.layout;
    to_src.newLayout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
    to_src.image = out.state.image;
    to_src.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    dep.pImageMemoryBarriers = &to_src;
    vkCmdPipelineBarrier2(cmd, &dep);
    vkCmdCopyImageToBuffer(cmd, out.state.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, down.buffer(), 1, &region);
    VkMemoryBarrier2 host{VK_STRUCTURE_TYPE_MEMORY_BARRIER_2};
    host.srcStageMask = VK_PIPELINE_STAGE_2_COPY_BIT;
    host.srcAccessMask = VK_ACCESS_2_TRANSFER_WRITE_BIT;
    host.dstStageMask = VK_PIPELINE_STAGE_2_HOST_BIT;
    host.dstAccessMask = VK_ACCESS_2_HOST_READ_BIT;
    VkDependencyInfo hdep{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
    hdep.memoryBarrierCount = 1;
    hdep.pMemoryBarriers = &host;
    vkCmdPipelineBarrier2(cmd, &hdep);
    vkEndCommandBuffer(cmd);
    VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    si.commandBufferCount = 1;
    si.pCommandBuffers = &cmd;
    ASSERT_EQ(vkQueueSubmit(queue, 1, &si, VK_NULL_HANDLE), VK_SUCCESS);
    ASSERT_EQ(vkQueueWaitIdle(queue), VK_SUCCESS);
    down.invalidate();
    CpuImage result(48, 32);
    std::memcpy(result.rgba.data(), down.mapped(), result.rgba.size() * 4);
    EXPECT_LT(reference::relative_l2(result, reference::bloom(input, bloom.config())), 1e-3);
  }
  vkDestroyCommandPool(device, pool, nullptr);
  vkDestroyDevice(device, nullptr);
}

TEST_F(ContextTest, AdoptRejectsNullHandlesAndBadQueueFamily) {
  EXPECT_THROW(Context::adopt({}), Error);
  const Context& mine = context();
  try {
    Context::adopt({mine.instance(), VK_API_VERSION_1_3, mine.physical_device(), mine.device(), 1000});
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("queue_family_index"), std::string::npos);
  }
}

// A device of the context's physical device, created with the given feature chain and glint's
// extensions (or none: push_descriptor false) (the engine's vkCreateDevice). Destroyed with the object.
struct EngineDevice {
  VkDevice device = VK_NULL_HANDLE;
  EngineDevice(const Context& mine, const void* features, bool push_descriptor = true) {
    float priority = 1.0f;
    VkDeviceQueueCreateInfo q{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
    q.queueFamilyIndex = mine.queue_family_index();
    q.queueCount = 1;
    q.pQueuePriorities = &priority;
    VkDeviceCreateInfo di{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
    di.pNext = features;
    di.queueCreateInfoCount = 1;
    di.pQueueCreateInfos = &q;
    di.enabledExtensionCount = push_descriptor ? kGlintDeviceExtensionCount : 0;
    di.ppEnabledExtensionNames = kGlintDeviceExtensions;
    if (vkCreateDevice(mine.physical_device(), &di, nullptr, &device) != VK_SUCCESS) device = VK_NULL_HANDLE;
  }
  EngineDevice(const EngineDevice&) = delete;
  EngineDevice& operator=(const EngineDevice&) = delete;
  ~EngineDevice() {
    if (device) vkDestroyDevice(device, nullptr);
  }
};

// Adopting `info` (with glint's extensions listed unless `list_extensions` is false) throws
// Error(code) whose message contains `names`.
void expect_adopt_error(AdoptInfo info, ErrorCode code, const std::string& names, bool list_extensions = true) {
  if (list_extensions) info = with_glint_extensions(info);
  try {
    Context::adopt(info);
    ADD_FAILURE() << "adopt accepted it; expected an error naming " << names;
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), code) << e.what();
    EXPECT_NE(std::string(e.what()).find(names), std::string::npos) << e.what();
  }
}

// Adopt refuses, before using the device, an instance below Vulkan 1.3 (or api_version not set) and
// a device whose feature chain lacks synchronization2 or maintenance4; each error names what is
// missing. These devices are valid Vulkan, so the layer stays silent (the fixture checks), and a
// chain that enables the features through the extension structs instead of
// VkPhysicalDeviceVulkan13Features is accepted.
TEST_F(ContextTest, AdoptChecksTheApiVersionsAndTheFeaturesGlintNeeds) {
  const Context& mine = context();
  const uint32_t family = mine.queue_family_index();
  for (uint32_t version : {0u, uint32_t(VK_API_VERSION_1_2), uint32_t(VK_API_VERSION_1_0)}) {
    expect_adopt_error({mine.instance(), version, mine.physical_device(), mine.device(), family},
                       ErrorCode::invalid_argument, "AdoptInfo::api_version = ");
  }
  expect_adopt_error({mine.instance(), VK_API_VERSION_1_2, mine.physical_device(), mine.device(), family},
                     ErrorCode::invalid_argument, "AdoptInfo::api_version = 1.2.0");

  VkPhysicalDeviceVulkan13Features no_sync2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES};
  no_sync2.maintenance4 = VK_TRUE;
  no_sync2.dynamicRendering = VK_TRUE;
  EngineDevice without_sync2(mine, &no_sync2);
  ASSERT_NE(without_sync2.device, VK_NULL_HANDLE);
  expect_adopt_error(
      {mine.instance(), VK_API_VERSION_1_3, mine.physical_device(), without_sync2.device, family, &no_sync2},
      ErrorCode::invalid_argument, "VkPhysicalDeviceVulkan13Features::synchronization2 is not enabled");

  VkPhysicalDeviceVulkan13Features no_m4{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES};
  no_m4.synchronization2 = VK_TRUE;
  VkPhysicalDeviceFeatures2 head{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};  // the chain as a whole
  head.pNext = &no_m4;
  EngineDevice without_m4(mine, &head);
  ASSERT_NE(without_m4.device, VK_NULL_HANDLE);
  expect_adopt_error({mine.instance(), VK_API_VERSION_1_3, mine.physical_device(), without_m4.device, family, &head},
                     ErrorCode::invalid_argument, "VkPhysicalDeviceVulkan13Features::maintenance4 is not enabled");

  // No feature chain at all: nothing is enabled, and a chain saying so is refused the same way.
  EngineDevice bare(mine, nullptr);
  ASSERT_NE(bare.device, VK_NULL_HANDLE);
  VkPhysicalDeviceFeatures2 nothing{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
  expect_adopt_error({mine.instance(), VK_API_VERSION_1_3, mine.physical_device(), bare.device, family, &nothing},
                     ErrorCode::invalid_argument, "synchronization2");

  // The same features through the structs of the extensions Vulkan 1.3 promoted.
  VkPhysicalDeviceMaintenance4Features m4{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MAINTENANCE_4_FEATURES};
  m4.maintenance4 = VK_TRUE;
  VkPhysicalDeviceSynchronization2Features s2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SYNCHRONIZATION_2_FEATURES};
  s2.synchronization2 = VK_TRUE;
  s2.pNext = &m4;
  EngineDevice promoted(mine, &s2);
  ASSERT_NE(promoted.device, VK_NULL_HANDLE);
  const Context ok = Context::adopt(with_glint_extensions(
      {mine.instance(), VK_API_VERSION_1_3, mine.physical_device(), promoted.device, family, &s2}));
  EXPECT_TRUE(ok.is_adopted());
  EXPECT_EQ(ok.device(), promoted.device);
  // A good adopt without a chain (every 1.3 device supports both features); a later instance
  // version is fine.
  EXPECT_TRUE(Context::adopt(with_glint_extensions({mine.instance(), VK_MAKE_API_VERSION(0, 1, 4, 0),
                                                    mine.physical_device(), mine.device(), family}))
                  .is_adopted());
}

// glint pushes every kernel's descriptors (VK_KHR_push_descriptor), and Vulkan cannot be asked
// which extensions a device was created with: adopt() refuses, naming the extension, a list that
// lacks it (no list, another extension only, or a count with a null list), and accepts the list of
// a device created with it. Each refused device is valid Vulkan, so the layer stays silent.
TEST_F(ContextTest, AdoptRefusesADeviceWithoutPushDescriptors) {
  const Context& mine = context();
  const uint32_t family = mine.queue_family_index();
  VkPhysicalDeviceVulkan13Features f13{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES};
  f13.synchronization2 = VK_TRUE;
  f13.maintenance4 = VK_TRUE;
  EngineDevice without(mine, &f13, false);
  ASSERT_NE(without.device, VK_NULL_HANDLE);
  const AdoptInfo base{mine.instance(), VK_API_VERSION_1_3, mine.physical_device(), without.device, family, &f13};
  expect_adopt_error(base, ErrorCode::invalid_argument,
                     "VK_KHR_push_descriptor is not in AdoptInfo::enabled_extensions", false);
  AdoptInfo other = base;
  const char* const swapchain[] = {VK_KHR_SWAPCHAIN_EXTENSION_NAME};
  other.enabled_extensions = swapchain;
  other.enabled_extension_count = 1;
  expect_adopt_error(other, ErrorCode::invalid_argument, "VK_KHR_push_descriptor", false);
  AdoptInfo null_list = base;
  null_list.enabled_extension_count = 2;
  expect_adopt_error(null_list, ErrorCode::invalid_argument, "AdoptInfo::enabled_extension_count = 2", false);

  EngineDevice with(mine, &f13, true);
  ASSERT_NE(with.device, VK_NULL_HANDLE);
  AdoptInfo good = base;
  good.device = with.device;
  const char* const listed[] = {VK_KHR_SWAPCHAIN_EXTENSION_NAME, VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME};
  good.enabled_extensions = listed;
  good.enabled_extension_count = 2;  // the extension need not come first
  const Context adopted = Context::adopt(good);
  EXPECT_TRUE(adopted.is_adopted());
}

// Compiled kernels (and samplers) are shared per context: a second pipeline of the same description compiles
// nothing, and a context-cached helper whose make() builds a pipeline (the demo starfield) does
// not wait on itself (it did when both used one lock: the demo hung).
TEST_F(ContextTest, PipelinesAreSharedAndACachedHelperCanMakeOne) {
  detail::PipelineDesc d;
  d.kernel_id = "image_copy_rgba16f";
  d.bindings = {VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE};
  d.push_constant_bytes = 48;
  d.workgroup = {8, 8};
  detail::ComputePipeline first(context(), d);
  const uint64_t objects = context().objects_created();
  detail::ComputePipeline second(context(), d);
  EXPECT_EQ(context().objects_created(), objects);
  EXPECT_EQ(first.set_layout(), second.set_layout());
  d.workgroup = {4, 4};
  detail::ComputePipeline other(context(), d);
  EXPECT_GT(context().objects_created(), objects);
  EXPECT_NE(other.set_layout(), first.set_layout());
  // Samplers are shared the same way.
  const VkSampler linear = detail::clamp_sampler(context(), VK_FILTER_LINEAR, VK_SAMPLER_MIPMAP_MODE_NEAREST, 0.0f);
  const uint64_t with_sampler = context().objects_created();
  EXPECT_EQ(detail::clamp_sampler(context(), VK_FILTER_LINEAR, VK_SAMPLER_MIPMAP_MODE_NEAREST, 0.0f), linear);
  EXPECT_EQ(context().objects_created(), with_sampler);
  EXPECT_NE(detail::clamp_sampler(context(), VK_FILTER_NEAREST, VK_SAMPLER_MIPMAP_MODE_NEAREST, 0.0f), linear);

  detail::OwnedImage target(context(), {32, 16}, VK_FORMAT_R16G16B16A16_SFLOAT, detail::kToolImageUsage);
  demo::StarfieldParams params;
  params.stars = 50;
  context().run_once([&](VkCommandBuffer cmd) { demo::record_starfield(context(), cmd, target.state, params); });
  const CpuImage img = detail::download(context(), target.state);
  float peak = 0.0f;
  for (float v : img.rgba) {
    ASSERT_TRUE(std::isfinite(v));
    peak = std::max(peak, v);
  }
  EXPECT_GT(peak, 0.0f);
}

// ContextOptions::kernel_statistics: off, nothing is captured; on, the pipelines made are captured
// with the driver's statistics exactly when the device has VK_KHR_pipeline_executable_properties
// and its pipelineExecutableInfo feature (lavapipe has both), and the validation layer sees a
// correct use of the extension.
TEST_F(ContextTest, KernelStatisticsAreCapturedOnlyWhenAskedAndSupported) {
  EXPECT_FALSE(context().kernel_statistics_enabled());
  EXPECT_TRUE(context().kernel_statistics().empty());
  ContextOptions options = tools::context_options_from_environment();
  options.validation = true;
  options.kernel_statistics = true;
  Context c = Context::create(options);
  uint32_t n = 0;
  vkEnumerateDeviceExtensionProperties(c.physical_device(), nullptr, &n, nullptr);
  std::vector<VkExtensionProperties> extensions(n);
  vkEnumerateDeviceExtensionProperties(c.physical_device(), nullptr, &n, extensions.data());
  bool has = false;
  for (const auto& e : extensions) has |= std::strcmp(e.extensionName, "VK_KHR_pipeline_executable_properties") == 0;
  VkPhysicalDevicePipelineExecutablePropertiesFeaturesKHR feature{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PIPELINE_EXECUTABLE_PROPERTIES_FEATURES_KHR};
  VkPhysicalDeviceFeatures2 features{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
  if (has) features.pNext = &feature;
  vkGetPhysicalDeviceFeatures2(c.physical_device(), &features);
  const bool supported = has && feature.pipelineExecutableInfo == VK_TRUE;
  EXPECT_EQ(c.kernel_statistics_enabled(), supported);
  EXPECT_TRUE(c.kernel_statistics().empty());  // no pipeline made yet
  detail::PipelineDesc d;
  d.kernel_id = "image_copy_rgba16f";
  d.bindings = {VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE};
  d.push_constant_bytes = 48;
  d.workgroup = {8, 8};
  detail::ComputePipeline pipeline(c, d);
  const auto stats = c.kernel_statistics();
  if (!supported) {
    EXPECT_TRUE(stats.empty());
  } else {
    ASSERT_FALSE(stats.empty());
    for (const auto& k : stats) {
      EXPECT_EQ(k.kernel, "image_copy_rgba16f");
      EXPECT_EQ(k.variant.rfind("8x8|48|", 0), 0u) << k.variant;
      EXPECT_FALSE(k.executable.empty());
      for (const auto& st : k.statistics) {
        EXPECT_FALSE(st.name.empty());
        EXPECT_FALSE(st.value.empty()) << st.name;
      }
    }
    size_t values = 0;
    for (const auto& k : stats) values += k.statistics.size();
    EXPECT_GT(values, 0u) << "the driver reports no statistic";
  }
  EXPECT_EQ(c.validation_messages(), 0u);
}

}  // namespace
}  // namespace glint::test

namespace glint::test {
namespace {

// Device memory is checked before it is allocated: a request beyond what the heap can give (its
// VK_EXT_memory_budget budget where the device has the extension, else its size) is an Error
// naming the bytes and the heap, not VK_ERROR_OUT_OF_DEVICE_MEMORY from deep inside an effect.
TEST_F(ContextTest, AllocationBeyondTheHeapIsRefusedBeforeAllocating) {
  detail::OwnedBuffer probe(context(), 256, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, false);
  VkMemoryRequirements req;
  vkGetBufferMemoryRequirements(context().device(), probe.buffer(), &req);
  auto& s = context().state();
  const uint32_t type = s.memory_type(req.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
  const uint32_t heap = s.memory.memoryTypes[type].heapIndex;
  req.size = s.memory.memoryHeaps[heap].size + req.alignment;
  const uint64_t objects = context().objects_created();
  try {
    (void)s.allocate(req, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, "a test request");
    ADD_FAILURE() << "no error for " << req.size << " bytes";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::unsupported_size);
    const std::string what = e.what();
    EXPECT_NE(
        what.find("a test request needs " + std::to_string(req.size) + " bytes of memory heap " + std::to_string(heap)),
        std::string::npos)
        << what;
  }
  EXPECT_EQ(context().objects_created(), objects);
  // A request that fits is allocated and counted.
  req.size = 4096;
  VkDeviceMemory m = s.allocate(req, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, "a small request");
  EXPECT_NE(m, VK_NULL_HANDLE);
  EXPECT_EQ(context().objects_created(), objects + 1);
  vkFreeMemory(context().device(), m, nullptr);
}

}  // namespace
}  // namespace glint::test
