// glint embedded in an engine, built only against the installed package (find_package(glint) or
// pkg-config glint): what README.md "Embedding" describes, end to end.
//
// The engine owns everything Vulkan: its instance (Vulkan 1.3; VK_LAYER_KHRONOS_validation with
// synchronization validation when GLINT_VALIDATION is set and not 0), its device (the features glint
// needs: synchronization2, maintenance4, and dynamicRendering for the raster flares), its images and
// buffers, its command buffer and its submission. glint adopts the device and records into the
// engine's command buffer, in one frame:
//   1. the engine's own compute pass (engine_fill.comp): HDR colour, depth, and glint's LOD
//      function evaluated from the installed GLSL header <glint/gpu/lod.glsl>;
//   2. Bloom of the colour;  3. GaussianBlur of the colour;
//   4. LensFlarePass: Hi-Z of the depth, cull of four lights (GlintFlareLight from
//      <glint/gpu/flare_types.h>), raster flare draw into a cleared image;
//   5. LodBatch of the same queries;
// then copies the results to host memory, submits once and checks them. Prints "ok" and exits 0;
// prints FAIL and exits 1 on a wrong result, an exception or any validation message.
#include <glint/bloom.h>
#include <glint/blur.h>
#include <glint/flare_pass.h>
#include <glint/glint.h>
#include <glint/gpu/flare_types.h>
#include <glint/gpu/lod_impl.h>
#include <glint/lod.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <iterator>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "engine_fill_spv.h"  // uint32_t engine_fill_spv[], from engine_fill.comp

namespace {

constexpr uint32_t kW = 128, kH = 96;
constexpr VkFormat kColor = VK_FORMAT_R16G16B16A16_SFLOAT;  // storage and blending are mandatory
constexpr VkFormat kDepth = VK_FORMAT_R32_SFLOAT;           // written by the engine's compute pass
constexpr float kBackground = 0.05f, kDisc = 20.0f, kDiscRadius = 3.0f;
constexpr int kDiscX = 32, kDiscY = 48;          // the visible light sits on the disc
constexpr int kOccluder[4] = {80, 32, 112, 64};  // near rectangle (depth 0.2)
constexpr uint32_t kQueries = 64;

// Push constants of engine_fill.comp (std430: every member 4-byte aligned, ivec4 at 48).
struct FillPush {
  GlintLodAtlas atlas;
  int32_t size[2];
  int32_t disc_center[2];
  int32_t occluder[4];
  float background, disc_value, disc_radius;
  uint32_t query_count;
};
static_assert(sizeof(FillPush) == 80 && offsetof(FillPush, occluder) == 48);

void vk(VkResult r, const char* what) {
  if (r != VK_SUCCESS) throw std::runtime_error(std::string(what) + " failed: VkResult " + std::to_string(r));
}

std::atomic<uint32_t> g_messages{0};

VKAPI_ATTR VkBool32 VKAPI_CALL on_message(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                          VkDebugUtilsMessageTypeFlagsEXT,
                                          const VkDebugUtilsMessengerCallbackDataEXT* data, void*) {
  if (severity >= VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT) {
    ++g_messages;
    std::printf("validation: %s\n", data && data->pMessage ? data->pMessage : "(no text)");
  }
  return VK_FALSE;
}

float half_to_float(uint16_t h) {
  const uint32_t sign = (h >> 15) & 1u, exp = (h >> 10) & 0x1fu, mant = h & 0x3ffu;
  float v;
  if (exp == 0)
    v = std::ldexp(float(mant), -24);
  else if (exp == 31)
    v = mant ? NAN : INFINITY;
  else
    v = std::ldexp(float(mant | 0x400u), int(exp) - 25);
  return sign ? -v : v;
}

// ---- The engine: instance, device, memory -------------------------------------------------------

struct Engine {
  VkInstance instance = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger = VK_NULL_HANDLE;
  VkPhysicalDevice physical = VK_NULL_HANDLE;
  VkDevice device = VK_NULL_HANDLE;
  uint32_t family = 0;
  VkQueue queue = VK_NULL_HANDLE;
  VkPhysicalDeviceMemoryProperties memory{};
  // The feature chain the device is created with; glint reads it (AdoptInfo::enabled_features).
  VkPhysicalDeviceVulkan13Features f13{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES};
  VkPhysicalDeviceFeatures2 features{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
  // The device extensions it is created with; glint reads them (AdoptInfo::enabled_extensions).
  const char* extensions[1] = {VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME};

  Engine() {
    const char* env = std::getenv("GLINT_VALIDATION");
    const bool validation = env && *env && std::strcmp(env, "0") != 0;
    VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
    app.pApplicationName = "glint_consumer";
    app.apiVersion = VK_API_VERSION_1_3;  // glint needs 1.3; AdoptInfo::api_version repeats it
    VkInstanceCreateInfo ii{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
    ii.pApplicationInfo = &app;
    const char* layer = "VK_LAYER_KHRONOS_validation";
    const char* ext = VK_EXT_DEBUG_UTILS_EXTENSION_NAME;
    VkValidationFeatureEnableEXT sync = VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT;
    VkValidationFeaturesEXT vf{VK_STRUCTURE_TYPE_VALIDATION_FEATURES_EXT};
    vf.enabledValidationFeatureCount = 1;
    vf.pEnabledValidationFeatures = &sync;
    VkDebugUtilsMessengerCreateInfoEXT mi{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
    mi.messageSeverity =
        VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
    mi.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                     VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
    mi.pfnUserCallback = on_message;
    if (validation) {
      ii.enabledLayerCount = 1;
      ii.ppEnabledLayerNames = &layer;
      ii.enabledExtensionCount = 1;
      ii.ppEnabledExtensionNames = &ext;
      vf.pNext = &mi;  // also reports instance creation and destruction
      ii.pNext = &vf;
    }
    vk(vkCreateInstance(&ii, nullptr, &instance), "vkCreateInstance");
    if (validation) {
      auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
          vkGetInstanceProcAddr(instance, "vkCreateDebugUtilsMessengerEXT"));
      if (!create) throw std::runtime_error("vkCreateDebugUtilsMessengerEXT not found");
      vk(create(instance, &mi, nullptr, &messenger), "vkCreateDebugUtilsMessengerEXT");
    }
    pick_device();

    // Exactly what glint documents (README.md "Embedding"): Vulkan 1.3 features and
    // VK_KHR_push_descriptor.
    f13.synchronization2 = VK_TRUE;
    f13.maintenance4 = VK_TRUE;
    f13.dynamicRendering = VK_TRUE;
    features.pNext = &f13;
    float priority = 1.0f;
    VkDeviceQueueCreateInfo q{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
    q.queueFamilyIndex = family;
    q.queueCount = 1;
    q.pQueuePriorities = &priority;
    VkDeviceCreateInfo di{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
    di.pNext = &features;
    di.queueCreateInfoCount = 1;
    di.pQueueCreateInfos = &q;
    di.enabledExtensionCount = 1;
    di.ppEnabledExtensionNames = extensions;
    vk(vkCreateDevice(physical, &di, nullptr, &device), "vkCreateDevice");
    vkGetDeviceQueue(device, family, 0, &queue);
    vkGetPhysicalDeviceMemoryProperties(physical, &memory);
  }

  // GLINT_DEVICE: an index or a part of the name (as glint's tools read it); else the first
  // Vulkan 1.3 device with a graphics + compute queue family, discrete GPUs first.
  void pick_device() {
    uint32_t n = 0;
    vk(vkEnumeratePhysicalDevices(instance, &n, nullptr), "vkEnumeratePhysicalDevices");
    std::vector<VkPhysicalDevice> all(n);
    vk(vkEnumeratePhysicalDevices(instance, &n, all.data()), "vkEnumeratePhysicalDevices");
    const char* want = std::getenv("GLINT_DEVICE");
    int best = -1;
    for (uint32_t i = 0; i < n; ++i) {
      VkPhysicalDeviceProperties p;
      vkGetPhysicalDeviceProperties(all[i], &p);
      uint32_t nf = 0;
      vkGetPhysicalDeviceQueueFamilyProperties(all[i], &nf, nullptr);
      std::vector<VkQueueFamilyProperties> fams(nf);
      vkGetPhysicalDeviceQueueFamilyProperties(all[i], &nf, fams.data());
      int fam = -1;
      for (uint32_t f = 0; f < nf && fam < 0; ++f) {
        const VkQueueFlags need = VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT;
        if ((fams[f].queueFlags & need) == need) fam = int(f);
      }
      if (p.apiVersion < VK_API_VERSION_1_3 || fam < 0) continue;
      if (want && *want) {
        const bool by_index = std::strspn(want, "0123456789") == std::strlen(want);
        if (by_index ? std::stoul(want) != i : std::string(p.deviceName).find(want) == std::string::npos) continue;
      }
      const bool discrete = p.deviceType == VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU;
      if (best < 0 || (discrete && !(want && *want))) {
        physical = all[i];
        family = uint32_t(fam);
        best = int(i);
        if (discrete) break;
      }
    }
    if (best < 0) throw std::runtime_error("no Vulkan 1.3 device with a graphics and compute queue");
    VkPhysicalDeviceProperties p;
    vkGetPhysicalDeviceProperties(physical, &p);
    std::printf("engine device: %s\n", p.deviceName);
  }

  uint32_t memory_type(uint32_t allowed, VkMemoryPropertyFlags wanted) const {
    for (uint32_t i = 0; i < memory.memoryTypeCount; ++i) {
      if ((allowed & (1u << i)) && (memory.memoryTypes[i].propertyFlags & wanted) == wanted) return i;
    }
    throw std::runtime_error("no suitable memory type");
  }

  Engine(const Engine&) = delete;
  Engine& operator=(const Engine&) = delete;
  ~Engine() {
    if (device) vkDestroyDevice(device, nullptr);
    if (messenger) {
      auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
          vkGetInstanceProcAddr(instance, "vkDestroyDebugUtilsMessengerEXT"));
      if (destroy) destroy(instance, messenger, nullptr);
    }
    if (instance) vkDestroyInstance(instance, nullptr);
  }
};

// An engine image with its memory and view, described to glint as a glint::Image.
struct EngineImage {
  VkDevice device;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  glint::Image image;

  EngineImage(const Engine& e, VkFormat format, VkImageUsageFlags usage) : device(e.device) {
    VkImageCreateInfo info{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
    info.imageType = VK_IMAGE_TYPE_2D;
    info.format = format;
    info.extent = {kW, kH, 1};
    info.mipLevels = 1;
    info.arrayLayers = 1;
    info.samples = VK_SAMPLE_COUNT_1_BIT;
    info.tiling = VK_IMAGE_TILING_OPTIMAL;
    info.usage = usage;
    vk(vkCreateImage(device, &info, nullptr, &image.image), "vkCreateImage");
    VkMemoryRequirements req;
    vkGetImageMemoryRequirements(device, image.image, &req);
    VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    alloc.allocationSize = req.size;
    alloc.memoryTypeIndex = e.memory_type(req.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
    vk(vkAllocateMemory(device, &alloc, nullptr, &memory), "vkAllocateMemory");
    vk(vkBindImageMemory(device, image.image, memory, 0), "vkBindImageMemory");
    VkImageViewCreateInfo view{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
    view.image = image.image;
    view.viewType = VK_IMAGE_VIEW_TYPE_2D;
    view.format = format;
    view.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    vk(vkCreateImageView(device, &view, nullptr, &image.view), "vkCreateImageView");
    image.format = format;
    image.extent = {kW, kH};
    image.usage = usage;
  }
  EngineImage(const EngineImage&) = delete;
  EngineImage& operator=(const EngineImage&) = delete;
  ~EngineImage() {
    vkDestroyImageView(device, image.view, nullptr);
    vkDestroyImage(device, image.image, nullptr);
    vkFreeMemory(device, memory, nullptr);
  }
};

// A host-visible, coherent engine buffer, described to glint as a glint::Buffer (size always set).
struct EngineBuffer {
  VkDevice device;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  void* mapped = nullptr;
  glint::Buffer buffer;

  EngineBuffer(const Engine& e, VkDeviceSize bytes, VkBufferUsageFlags usage) : device(e.device) {
    VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    info.size = bytes;
    info.usage = usage;
    vk(vkCreateBuffer(device, &info, nullptr, &buffer.buffer), "vkCreateBuffer");
    VkMemoryRequirements req;
    vkGetBufferMemoryRequirements(device, buffer.buffer, &req);
    VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    alloc.allocationSize = req.size;
    alloc.memoryTypeIndex =
        e.memory_type(req.memoryTypeBits, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
    vk(vkAllocateMemory(device, &alloc, nullptr, &memory), "vkAllocateMemory");
    vk(vkBindBufferMemory(device, buffer.buffer, memory, 0), "vkBindBufferMemory");
    vk(vkMapMemory(device, memory, 0, VK_WHOLE_SIZE, 0, &mapped), "vkMapMemory");
    buffer.size = bytes;
    buffer.usage = usage;
  }
  EngineBuffer(const EngineBuffer&) = delete;
  EngineBuffer& operator=(const EngineBuffer&) = delete;
  ~EngineBuffer() {
    vkDestroyBuffer(device, buffer.buffer, nullptr);
    vkFreeMemory(device, memory, nullptr);
  }
  template <class T>
  T* as() const {
    return static_cast<T*>(mapped);
  }
};

void image_barrier(VkCommandBuffer cmd, glint::Image& img, VkImageLayout layout, VkPipelineStageFlags2 stage,
                   VkAccessFlags2 access) {
  VkImageMemoryBarrier2 b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2};
  b.srcStageMask = img.stage;
  b.srcAccessMask = img.access;
  b.dstStageMask = stage;
  b.dstAccessMask = access;
  b.oldLayout = img.layout;
  b.newLayout = layout;
  b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  b.image = img.image;
  b.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
  VkDependencyInfo dep{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
  dep.imageMemoryBarrierCount = 1;
  dep.pImageMemoryBarriers = &b;
  vkCmdPipelineBarrier2(cmd, &dep);
  img.layout = layout;
  img.stage = stage;
  img.access = access;
}

// ---- The engine's compute pass ------------------------------------------------------------------

struct FillPass {
  VkDevice device;
  VkDescriptorSetLayout set_layout = VK_NULL_HANDLE;
  VkPipelineLayout layout = VK_NULL_HANDLE;
  VkPipeline pipeline = VK_NULL_HANDLE;
  VkDescriptorPool pool = VK_NULL_HANDLE;
  VkDescriptorSet set = VK_NULL_HANDLE;

  FillPass(const Engine& e, const glint::Image& hdr, const glint::Image& depth, const glint::Buffer& queries,
           const glint::Buffer& levels)
      : device(e.device) {
    const VkDescriptorSetLayoutBinding b[4] = {
        {0, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr},
        {1, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr},
        {2, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr},
        {3, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr},
    };
    VkDescriptorSetLayoutCreateInfo sl{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
    sl.bindingCount = 4;
    sl.pBindings = b;
    vk(vkCreateDescriptorSetLayout(device, &sl, nullptr, &set_layout), "vkCreateDescriptorSetLayout");
    VkPushConstantRange range{VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(FillPush)};
    VkPipelineLayoutCreateInfo pl{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
    pl.setLayoutCount = 1;
    pl.pSetLayouts = &set_layout;
    pl.pushConstantRangeCount = 1;
    pl.pPushConstantRanges = &range;
    vk(vkCreatePipelineLayout(device, &pl, nullptr, &layout), "vkCreatePipelineLayout");
    VkShaderModuleCreateInfo sm{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
    sm.codeSize = sizeof(engine_fill_spv);
    sm.pCode = engine_fill_spv;
    VkShaderModule module;
    vk(vkCreateShaderModule(device, &sm, nullptr, &module), "vkCreateShaderModule");
    VkComputePipelineCreateInfo ci{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
    ci.stage = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
    ci.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    ci.stage.module = module;
    ci.stage.pName = "main";
    ci.layout = layout;
    const VkResult r = vkCreateComputePipelines(device, VK_NULL_HANDLE, 1, &ci, nullptr, &pipeline);
    vkDestroyShaderModule(device, module, nullptr);
    vk(r, "vkCreateComputePipelines");
    const VkDescriptorPoolSize sizes[2] = {{VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 2},
                                           {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 2}};
    VkDescriptorPoolCreateInfo pi{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
    pi.maxSets = 1;
    pi.poolSizeCount = 2;
    pi.pPoolSizes = sizes;
    vk(vkCreateDescriptorPool(device, &pi, nullptr, &pool), "vkCreateDescriptorPool");
    VkDescriptorSetAllocateInfo ai{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
    ai.descriptorPool = pool;
    ai.descriptorSetCount = 1;
    ai.pSetLayouts = &set_layout;
    vk(vkAllocateDescriptorSets(device, &ai, &set), "vkAllocateDescriptorSets");
    const VkDescriptorImageInfo images[2] = {{VK_NULL_HANDLE, hdr.view, VK_IMAGE_LAYOUT_GENERAL},
                                             {VK_NULL_HANDLE, depth.view, VK_IMAGE_LAYOUT_GENERAL}};
    const VkDescriptorBufferInfo buffers[2] = {{queries.buffer, 0, queries.size}, {levels.buffer, 0, levels.size}};
    VkWriteDescriptorSet w[4];
    for (uint32_t i = 0; i < 4; ++i) {
      w[i] = {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
      w[i].dstSet = set;
      w[i].dstBinding = i;
      w[i].descriptorCount = 1;
      w[i].descriptorType = i < 2 ? VK_DESCRIPTOR_TYPE_STORAGE_IMAGE : VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
      if (i < 2)
        w[i].pImageInfo = &images[i];
      else
        w[i].pBufferInfo = &buffers[i - 2];
    }
    vkUpdateDescriptorSets(device, 4, w, 0, nullptr);
  }
  FillPass(const FillPass&) = delete;
  FillPass& operator=(const FillPass&) = delete;
  ~FillPass() {
    vkDestroyDescriptorPool(device, pool, nullptr);
    vkDestroyPipeline(device, pipeline, nullptr);
    vkDestroyPipelineLayout(device, layout, nullptr);
    vkDestroyDescriptorSetLayout(device, set_layout, nullptr);
  }

  void record(VkCommandBuffer cmd, const FillPush& push) const {
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline);
    vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, layout, 0, 1, &set, 0, nullptr);
    vkCmdPushConstants(cmd, layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof push, &push);
    vkCmdDispatch(cmd, (kW + 7) / 8, (kH + 7) / 8, 1);
  }
};

// ---- Checks -------------------------------------------------------------------------------------

struct Failures {
  int count = 0;
  void check(bool ok, const std::string& what) {
    if (!ok) {
      ++count;
      std::printf("FAIL: %s\n", what.c_str());
    }
  }
};

// Channel c of pixel (x, y) of an RGBA16F image copied tightly to host memory.
float texel(const uint16_t* px, int x, int y, int c) { return half_to_float(px[(size_t(y) * kW + x) * 4 + c]); }

GlintFlareLight light_at(float ndc_x, float ndc_y, float ndc_z, uint32_t enabled) {
  GlintFlareLight l{};
  l.position_x = ndc_x;  // view_proj is the identity: positions are NDC with w = 1
  l.position_y = ndc_y;
  l.position_z = ndc_z;
  l.intensity = 1.0f;
  l.color_r = l.color_g = l.color_b = 1.0f;
  l.size_px = 8.0f;
  l.element = GLINT_FLARE_ELEMENT_GLOW;
  l.enabled = enabled;
  return l;
}

int run() {
  Failures f;
  {
    Engine engine;
    // glint adopts the engine's objects; every requirement is checked here (Error if one is missing).
    glint::AdoptInfo adopt;
    adopt.instance = engine.instance;
    adopt.api_version = VK_API_VERSION_1_3;
    adopt.physical_device = engine.physical;
    adopt.device = engine.device;
    adopt.queue_family_index = engine.family;
    adopt.enabled_features = &engine.features;
    adopt.enabled_extensions = engine.extensions;
    adopt.enabled_extension_count = 1;
    const glint::Context ctx = glint::Context::adopt(adopt);
    std::printf("glint %d.%d.%d adopted %s\n", glint::kVersionMajor, glint::kVersionMinor, glint::kVersionPatch,
                ctx.info().name.c_str());

    // The engine's resources.
    EngineImage hdr(engine, kColor,
                    VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT);
    EngineImage depth(engine, kDepth, VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_SAMPLED_BIT);
    EngineImage bloomed(engine, kColor, VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT);
    EngineImage blurred(engine, kColor, VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT);
    EngineImage flares(
        engine, kColor,
        VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT);
    const VkDeviceSize image_bytes = VkDeviceSize(kW) * kH * 8;
    EngineBuffer readback(engine, 3 * image_bytes + sizeof(GlintFlareStats) + 4 * sizeof(GlintFlareLightResult),
                          VK_BUFFER_USAGE_TRANSFER_DST_BIT);
    EngineBuffer lights(engine, 4 * sizeof(GlintFlareLight), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    EngineBuffer queries(engine, kQueries * sizeof(GlintLodQuery), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    EngineBuffer levels_glint(engine, kQueries * sizeof(float), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    EngineBuffer levels_engine(engine, kQueries * sizeof(float), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);

    // Lights: 0 on the disc in front of far depth (visible), 1 behind the near rectangle
    // (occluded), 2 outside the frustum margin, 3 disabled. Pixel = (ndc * 0.5 + 0.5) * size.
    const float ndc_y = 2.0f * kDiscY / kH - 1.0f;
    lights.as<GlintFlareLight>()[0] = light_at(2.0f * kDiscX / kW - 1.0f, ndc_y, 0.5f, 1);
    lights.as<GlintFlareLight>()[1] = light_at(2.0f * 96 / kW - 1.0f, ndc_y, 0.5f, 1);
    lights.as<GlintFlareLight>()[2] = light_at(5.0f, 0.0f, 0.5f, 1);
    lights.as<GlintFlareLight>()[3] = light_at(0.0f, 0.0f, 0.5f, 0);

    // LOD queries: tiles of a 1024^2 atlas, derivatives spread over 2^-12 .. 2^2 of the tile per
    // pixel (levels 0 to 10 and clamped beyond), anisotropic with maxAnisotropy 8.
    glint::LodAtlasConfig atlas;
    atlas.atlas_width = atlas.atlas_height = 1024;
    atlas.levels = 11;
    atlas.anisotropic = true;
    atlas.max_anisotropy = 8.0f;
    std::vector<glint::LodQuery> qs(kQueries);
    for (uint32_t i = 0; i < kQueries; ++i) {
      glint::LodQuery& q = qs[i];
      const float s = std::ldexp(1.0f, int(i % 15) - 12);
      q.dudx = s * (1.0f + 0.1f * float(i % 3));
      q.dvdx = s * 0.25f * float(i % 5);
      q.dudy = -s * 0.125f * float(i % 4);
      q.dvdy = s * (0.5f + float(i % 7));
      q.tex_w = float(64u << (i % 4));
      q.tex_h = float(32u << (i % 5));
      q.off_x = float(16 * (i % 8));
      q.off_y = float(8 * (i % 16));
    }
    std::memcpy(queries.mapped, qs.data(), kQueries * sizeof(GlintLodQuery));
    FillPush push{};
    push.atlas = {1024.0f, 1024.0f, 11.0f, 0.0f, 8.0f, -1.0f, GLINT_LOD_ANISOTROPIC, 0};
    push.size[0] = kW;
    push.size[1] = kH;
    push.disc_center[0] = kDiscX;
    push.disc_center[1] = kDiscY;
    std::copy(std::begin(kOccluder), std::end(kOccluder), push.occluder);
    push.background = kBackground;
    push.disc_value = kDisc;
    push.disc_radius = kDiscRadius;
    push.query_count = kQueries;

    // glint's effects, made once (an engine makes them at load time).
    glint::Bloom bloom(ctx);
    glint::GaussianBlur blur(ctx);
    glint::FlarePassConfig fpc;
    fpc.extent = {kW, kH};
    fpc.color_format = kColor;
    fpc.depth_format = kDepth;
    fpc.cull.capacity = 16;
    fpc.cull.max_lights = 4;
    fpc.per_light_results = true;
    fpc.draw = glint::FlareDrawPath::raster;
    glint::LensFlarePass flare_pass(ctx, fpc);
    glint::LodBatch lod(ctx);
    FillPass fill(engine, hdr.image, depth.image, queries.buffer, levels_engine.buffer);

    VkCommandPoolCreateInfo pi{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    pi.queueFamilyIndex = engine.family;
    VkCommandPool pool;
    vk(vkCreateCommandPool(engine.device, &pi, nullptr, &pool), "vkCreateCommandPool");
    VkCommandBufferAllocateInfo ai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    ai.commandPool = pool;
    ai.commandBufferCount = 1;
    VkCommandBuffer cmd;
    vk(vkAllocateCommandBuffers(engine.device, &ai, &cmd), "vkAllocateCommandBuffers");
    VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    vk(vkBeginCommandBuffer(cmd, &bi), "vkBeginCommandBuffer");

    // 1. The engine's pass. Its last use of each image goes into the glint::Image state fields.
    image_barrier(cmd, hdr.image, VK_IMAGE_LAYOUT_GENERAL, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                  VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
    image_barrier(cmd, depth.image, VK_IMAGE_LAYOUT_GENERAL, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                  VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
    fill.record(cmd, push);
    image_barrier(cmd, flares.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_PIPELINE_STAGE_2_CLEAR_BIT,
                  VK_ACCESS_2_TRANSFER_WRITE_BIT);
    const VkClearColorValue zero{};
    const VkImageSubresourceRange range{VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    vkCmdClearColorImage(cmd, flares.image.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &zero, 1, &range);

    // 2-5. glint, recording into the engine's command buffer; each call writes its barriers from
    // the state fields and leaves them describing its own last use.
    bloom.record(cmd, hdr.image, bloomed.image);
    blur.record(cmd, hdr.image, blurred.image);
    const float identity[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    flare_pass.record(cmd, flares.image, depth.image, lights.buffer, 4, identity, glint::FlareConfig{});
    lod.record(cmd, queries.buffer, levels_glint.buffer, kQueries, atlas);

    // Read back: images and the statistics and results buffers to `readback`, then host reads.
    VkBufferImageCopy region{};
    region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    region.imageExtent = {kW, kH, 1};
    EngineImage* to_read[3] = {&bloomed, &blurred, &flares};
    for (int i = 0; i < 3; ++i) {
      image_barrier(cmd, to_read[i]->image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_PIPELINE_STAGE_2_COPY_BIT,
                    VK_ACCESS_2_TRANSFER_READ_BIT);
      region.bufferOffset = VkDeviceSize(i) * image_bytes;
      vkCmdCopyImageToBuffer(cmd, to_read[i]->image.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, readback.buffer.buffer,
                             1, &region);
    }
    glint::Buffer* glint_buffers[2] = {&flare_pass.stats(), &flare_pass.results()};
    VkBufferMemoryBarrier2 bb[2];
    for (int i = 0; i < 2; ++i) {
      bb[i] = {VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER_2};
      bb[i].srcStageMask = glint_buffers[i]->stage;
      bb[i].srcAccessMask = glint_buffers[i]->access;
      bb[i].dstStageMask = VK_PIPELINE_STAGE_2_COPY_BIT;
      bb[i].dstAccessMask = VK_ACCESS_2_TRANSFER_READ_BIT;
      bb[i].srcQueueFamilyIndex = bb[i].dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
      bb[i].buffer = glint_buffers[i]->buffer;
      bb[i].offset = glint_buffers[i]->offset;
      bb[i].size = VK_WHOLE_SIZE;
    }
    VkDependencyInfo dep{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
    dep.bufferMemoryBarrierCount = 2;
    dep.pBufferMemoryBarriers = bb;
    vkCmdPipelineBarrier2(cmd, &dep);
    VkBufferCopy stats_copy{flare_pass.stats().offset, 3 * image_bytes, sizeof(GlintFlareStats)};
    vkCmdCopyBuffer(cmd, flare_pass.stats().buffer, readback.buffer.buffer, 1, &stats_copy);
    VkBufferCopy results_copy{flare_pass.results().offset, 3 * image_bytes + sizeof(GlintFlareStats),
                              4 * sizeof(GlintFlareLightResult)};
    vkCmdCopyBuffer(cmd, flare_pass.results().buffer, readback.buffer.buffer, 1, &results_copy);
    // Transfers and both LOD passes' storage writes, to the host.
    VkMemoryBarrier2 to_host{VK_STRUCTURE_TYPE_MEMORY_BARRIER_2};
    to_host.srcStageMask = VK_PIPELINE_STAGE_2_COPY_BIT | VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT;
    to_host.srcAccessMask = VK_ACCESS_2_TRANSFER_WRITE_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT;
    to_host.dstStageMask = VK_PIPELINE_STAGE_2_HOST_BIT;
    to_host.dstAccessMask = VK_ACCESS_2_HOST_READ_BIT;
    VkDependencyInfo hdep{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
    hdep.memoryBarrierCount = 1;
    hdep.pMemoryBarriers = &to_host;
    vkCmdPipelineBarrier2(cmd, &hdep);
    vk(vkEndCommandBuffer(cmd), "vkEndCommandBuffer");

    VkFenceCreateInfo fi{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    VkFence fence;
    vk(vkCreateFence(engine.device, &fi, nullptr, &fence), "vkCreateFence");
    VkCommandBufferSubmitInfo cbi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_SUBMIT_INFO};
    cbi.commandBuffer = cmd;
    VkSubmitInfo2 si{VK_STRUCTURE_TYPE_SUBMIT_INFO_2};
    si.commandBufferInfoCount = 1;
    si.pCommandBufferInfos = &cbi;
    vk(vkQueueSubmit2(engine.queue, 1, &si, fence), "vkQueueSubmit2");
    vk(vkWaitForFences(engine.device, 1, &fence, VK_TRUE, UINT64_MAX), "vkWaitForFences");
    vkDestroyFence(engine.device, fence, nullptr);
    vkDestroyCommandPool(engine.device, pool, nullptr);

    // ---- Checks. Colour images are fp16: a stored value is within 2^-11 relative of the fp32 one.
    const auto* img = readback.as<const uint16_t>();
    const uint16_t* bl = img;
    const uint16_t* gb = img + kW * kH * 4;
    const uint16_t* fl = img + 2 * kW * kH * 4;
    auto input_at = [](int x, int y) {  // what engine_fill.comp wrote (fp16-exact: 20 and 0.05 rounded)
      const float dx = float(x) + 0.5f - float(kDiscX), dy = float(y) + 0.5f - float(kDiscY);
      return dx * dx + dy * dy <= kDiscRadius * kDiscRadius ? kDisc : kBackground;
    };
    constexpr double kHalfUlp = 1.0 / 2048.0;  // fp16 rounding, relative

    // Bloom adds non-negative light (output = input + intensity x bloom, docs/BLOOM.md), so every
    // texel is at least its input up to two fp16 roundings, and the disc (above the threshold)
    // spreads light onto the background around it.
    bool bloom_ok = true;
    for (int y = 0; y < int(kH); ++y) {
      for (int x = 0; x < int(kW); ++x) {
        for (int c = 0; c < 3; ++c) {
          const float v = texel(bl, x, y, c);
          if (!std::isfinite(v) || v < input_at(x, y) * (1.0 - 3 * kHalfUlp)) bloom_ok = false;
        }
      }
    }
    f.check(bloom_ok, "bloom: a texel is not finite or below its input");
    const float glow = texel(bl, kDiscX + 8, kDiscY, 0) - kBackground;
    std::printf("bloom: %u levels; 8 px right of the disc +%.4f over the background\n", bloom.levels(), double(glow));
    f.check(glow > 0.01f, "bloom: no glow next to the bright disc");

    // Gaussian blur (sigma 4 px): a normalized filter with non-negative weights, clamp-to-edge on a
    // constant border. So the image sum is kept (the disc is 8 sigma from every edge), no texel
    // goes below the background, and the disc's peak drops: under an exact Gaussian a 3 px disc
    // keeps 1 - exp(-9 / 32) = 25% of its height at the centre; 30% leaves room for the method's
    // modelled error (GaussianBlurConfig::max_relative_error, 1%) and the disc's pixelation.
    double sum_in = 0, sum_out = 0;
    float lo = INFINITY, hi = -INFINITY;
    for (int y = 0; y < int(kH); ++y) {
      for (int x = 0; x < int(kW); ++x) {
        sum_in += input_at(x, y);
        const float v = texel(gb, x, y, 0);
        sum_out += v;
        lo = std::min(lo, v);
        hi = std::max(hi, std::isfinite(v) ? v : INFINITY);
      }
    }
    std::printf("blur: %s, sum %.3f (input %.3f), range [%.4f, %.4f]\n", glint::blur_method_name(blur.choice().method),
                sum_out, sum_in, double(lo), double(hi));
    f.check(std::fabs(sum_out - sum_in) <= 0.01 * sum_in, "blur: the image sum changed by more than 1%");
    f.check(lo >= kBackground * (1.0 - 4 * kHalfUlp) && hi <= kDisc * 0.3f,
            "blur: a texel outside [background, 30% of the disc]");

    // Lens flares: the statistics and per-light results of the cull, and the draw.
    GlintFlareStats stats;
    std::memcpy(&stats, img + 3 * kW * kH * 4, sizeof stats);
    GlintFlareLightResult results[4];
    std::memcpy(results, reinterpret_cast<const char*>(img) + 3 * image_bytes + sizeof stats, sizeof results);
    std::printf("flares: total %u visible %u occluded %u frustum %u disabled %u overflow %u\n", stats.total,
                stats.visible, stats.occluded, stats.frustum_culled, stats.disabled, stats.overflow);
    f.check(stats.total == 4 && stats.visible == 1 && stats.occluded == 1 && stats.frustum_culled == 1 &&
                stats.disabled == 1 && stats.overflow == 0,
            "flares: statistics are not 4 lights = 1 visible + 1 occluded + 1 frustum + 1 disabled");
    const uint32_t want[4] = {GLINT_FLARE_VISIBLE, GLINT_FLARE_OCCLUDED, GLINT_FLARE_FRUSTUM, GLINT_FLARE_DISABLED};
    for (int i = 0; i < 4; ++i) {
      f.check(results[i].culled == want[i], "flares: light " + std::to_string(i) + " has the wrong cull result");
    }
    f.check(results[0].visible_fraction == 1.0f, "flares: the visible light is not fully visible");
    bool flare_ok = true;
    double flare_sum = 0;
    for (size_t i = 0; i < size_t(kW) * kH; ++i) {
      for (int c = 0; c < 4; ++c) {
        const float v = half_to_float(fl[i * 4 + c]);
        if (!std::isfinite(v) || v < 0.0f || (c == 3 && v != 0.0f)) flare_ok = false;  // alpha never written
        if (c < 3) flare_sum += v;
      }
    }
    const float at_light = texel(fl, kDiscX, kDiscY, 0);
    std::printf("flares: %.4f at the visible light, %.2f in all\n", double(at_light), flare_sum);
    f.check(flare_ok, "flares: a texel is negative or not finite, or alpha was written");
    f.check(at_light > 0.01f, "flares: nothing drawn at the visible light");

    // LOD: glint's batch kernel, the engine's own shader (same installed GLSL source) and the C++
    // twin agree. The GPU's log2 is within 3 ulp and its sqrt within 2^-21 relative (Vulkan
    // "Precision and Operation of SPIR-V Instructions"): |lambda| < 16 differs by under 1e-5.
    const float* lg = levels_glint.as<const float>();
    const float* le = levels_engine.as<const float>();
    double worst = 0;
    std::set<int> distinct;
    for (uint32_t i = 0; i < kQueries; ++i) {
      const float cpu = glint::lod_level(qs[i], atlas);
      const glint::LodQuery& q = qs[i];
      const GlintLodQuery g{q.dudx, q.dvdx, q.dudy, q.dvdy, q.tex_w, q.tex_h, q.off_x, q.off_y};
      const float twin = glint::lod_math::glint_lod(g, push.atlas);
      f.check(std::fabs(twin - cpu) <= 1e-6f,
              "lod: glint::lod_math and glint::lod_level differ at query " + std::to_string(i));
      worst = std::max({worst, std::fabs(double(lg[i]) - cpu), std::fabs(double(le[i]) - cpu)});
      if (!std::isfinite(lg[i]) || !std::isfinite(le[i])) worst = INFINITY;
      distinct.insert(int(std::lround(cpu)));
    }
    std::printf("lod: %zu distinct levels; worst |GPU - C++| %.2e\n", distinct.size(), worst);
    f.check(worst <= 1e-4, "lod: the GPU levels differ from glint::lod_level by more than 1e-4");
    f.check(distinct.size() >= 6, "lod: the queries cover fewer than 6 levels (the check would be weak)");
  }  // glint's objects and the adopted Context go first, then the engine's device and instance
  if (g_messages.load() != 0) {
    std::printf("FAIL: %u validation message(s)\n", g_messages.load());
    return 1;
  }
  return f.count ? 1 : 0;
}

}  // namespace

int main() {
  try {
    const int rc = run();
    if (rc == 0) std::printf("ok\n");
    return rc;
  } catch (const std::exception& e) {
    std::printf("FAIL: %s\n", e.what());
    return 1;
  }
}
