// glint: Vulkan compute kernels for HDR post-processing.
//
// This header holds what every effect shares: the error type, the Vulkan context (standalone or
// adopted from an engine), the view of a caller's image that effects read and write, and a GPU
// timestamp profiler. One header per effect (bloom.h, ...) holds that effect's config and class.
//
// Conventions used across the API:
// - Every failure throws glint::Error. Its message names the parameter, the value and the accepted
//   range. Validation happens before anything is recorded, so a throwing record() leaves the
//   command buffer exactly as it was.
// - Effects record into the caller's VkCommandBuffer and never submit, wait or read back.
// - Images are described by glint::Image, which also carries the caller's last use of the image
//   (layout, stage, access). Effects write the state they leave the image in back into it.
// - Threads. A Context may be used from several threads at once: its const member functions,
//   run_once() (submissions are serialized inside), and constructing, preparing and destroying
//   effects on it (the shared kernel and sampler caches are locked). An effect object is not:
//   call one effect's members from one thread at a time. Different effects may record into
//   different command buffers on different threads at the same time, as engines record in
//   parallel. Command buffers, pools and queues follow Vulkan's external synchronization rules;
//   glint touches only the command buffer passed to record().
// - Frames in flight. Effects whose images depend on the input size (Bloom, BlurPyramid,
//   GaussianBlur) keep them per size, so one effect may be recorded at several sizes in one
//   command buffer or in consecutive frames (dynamic resolution, several views). A size's images
//   are destroyed only once no submitted work can use them: the engine calls
//   Context::begin_frame() once per frame, and a size unused for ContextOptions::frames_in_flight
//   frames is retired by the effect's next record(), prepare() or release_unused(). Work recorded
//   inside run_once() is complete when it returns, so run_once() users need nothing else.
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace glint {

inline constexpr int kVersionMajor = 0;
inline constexpr int kVersionMinor = 1;
inline constexpr int kVersionPatch = 0;

/// The most sizes (with output format and config shape) an effect keeps images for at once. A
/// record() that needs a new one while all are held by frames that may still be in flight throws
/// Error(invalid_argument) before recording anything (see Context::begin_frame()).
inline constexpr uint32_t kMaxCachedSizes = 32;

/// What kind of failure an Error reports.
enum class ErrorCode {
  invalid_argument,    //!< a config value or argument is out of range, NaN or inconsistent
  unsupported_format,  //!< an image format the effect cannot read or write
  unsupported_size,    //!< zero size, or larger than the device allows
  missing_usage,       //!< an image lacks a usage flag the effect needs
  vulkan_failure,      //!< a Vulkan call returned an error
  no_device,           //!< no Vulkan device matches the request
  io_failure,          //!< a file could not be read or written (CLI and io helpers)
};

/// The one exception type glint throws.
class Error : public std::runtime_error {
 public:
  Error(ErrorCode code, const std::string& message) : std::runtime_error(message), code_(code) {}
  ErrorCode code() const noexcept { return code_; }

 private:
  ErrorCode code_;
};

/// A description of one Vulkan physical device, as listed by list_devices().
struct DeviceDescription {
  uint32_t index = 0;           //!< position in vkEnumeratePhysicalDevices order
  std::string name;             //!< VkPhysicalDeviceProperties::deviceName
  VkPhysicalDeviceType type{};  //!< discrete, integrated, CPU (lavapipe), ...
  uint32_t api_version = 0;     //!< VK_MAKE_API_VERSION encoded
};

/// Options for a standalone context (one that creates its own instance and device).
struct ContextOptions {
  /// Which device: a decimal index into list_devices(), or a case-insensitive substring of the
  /// device name. Empty: the first discrete GPU, else the first integrated GPU, else the first CPU
  /// device (lavapipe). The library reads no environment variable; the glint command, the tests
  /// and the benchmarks map GLINT_DEVICE to this field.
  std::string device;
  /// Enable VK_LAYER_KHRONOS_validation with synchronization validation. Messages are counted
  /// (validation_messages()) and printed to stderr.
  bool validation = false;
  /// Also enable GPU-assisted validation (instrumented shaders check descriptor and buffer accesses
  /// on the device; slow). Needs `validation`.
  bool gpu_assisted_validation = false;
  /// The 2-D workgroup of every image kernel, for tuning benchmarks: 0x0 (default) lets each
  /// kernel choose from the device's limits; else W x H with W, H >= 1 and W * H at most
  /// maxComputeWorkGroupInvocations (checked by create()). Setting it also makes Bloom's
  /// karis_smooth first step use its box-means kernel on CPU devices too (GPUs always do;
  /// docs/BLOOM.md), which is how the tests reach that kernel on lavapipe.
  VkExtent2D workgroup_2d{0, 0};
  /// How many frames the caller may have submitted and not yet waited for (1 to 16): when
  /// Context::begin_frame() starts frame F, every command buffer recorded in frame
  /// F - frames_in_flight or earlier has completed. Effects keep a size's images for this many
  /// frames after its last use (see Context::begin_frame()).
  uint32_t frames_in_flight = 3;
  /// Capture the driver's statistics of every compute pipeline glint makes (register count,
  /// shared memory, spills, instruction count: whatever the driver reports), for
  /// Context::kernel_statistics(). VK_KHR_pipeline_executable_properties and its
  /// pipelineExecutableInfo feature are enabled only where the device supports them
  /// (Context::kernel_statistics_enabled() says whether they were); off (the default), the device
  /// and the pipelines are made exactly as without this option. For tuning tools (glint_bench
  /// --kernel_stats).
  bool kernel_statistics = false;
};

/// One statistic of a pipeline executable (VkPipelineExecutableStatisticKHR), as the driver names it.
struct KernelStatistic {
  std::string name;         //!< e.g. "Register count" (driver-specific)
  std::string description;  //!< the driver's description
  std::string value;        //!< the value as text (bool32, int64, uint64 or float64 in the driver's unit)
};

/// The statistics of one executable (shader stage or driver-internal part) of one compute pipeline.
struct KernelStatistics {
  std::string kernel;      //!< the kernel id, e.g. "object_cull_main"
  std::string variant;     //!< workgroup, specialization and bindings of this pipeline of the kernel
  std::string executable;  //!< VkPipelineExecutablePropertiesKHR::name
  uint32_t subgroup_size = 0;
  std::vector<KernelStatistic> statistics;
};

/// What an engine hands glint when it adopts the engine's own Vulkan objects. glint never
/// destroys them and never submits work: the engine records glint's commands and submits them.
/// Context::adopt() checks everything below and throws Error naming what is missing; README.md
/// "Embedding" lists what an engine must enable, and tests/consumer is a complete example.
struct AdoptInfo {
  VkInstance instance = VK_NULL_HANDLE;  //!< must not be null
  /// The VkApplicationInfo::apiVersion the engine created `instance` with (Vulkan cannot be asked
  /// for it): VK_API_VERSION_1_3 or later. Required: 0 (not set) is refused like 1.2.
  uint32_t api_version = 0;
  VkPhysicalDevice physical_device = VK_NULL_HANDLE;  //!< must not be null; apiVersion >= 1.3
  /// Must not be null; created on physical_device with the Vulkan 1.3 features synchronization2
  /// (every barrier is vkCmdPipelineBarrier2) and maintenance4 (kernels size their workgroups by
  /// specialization, LocalSizeId) enabled, and dynamicRendering for LensFlare's raster path
  /// (LensFlarePass with FlareDrawPath::raster), and the device extension VK_KHR_push_descriptor
  /// (listed in enabled_extensions).
  VkDevice device = VK_NULL_HANDLE;
  uint32_t queue_family_index = 0;  //!< family the command buffers come from; must support compute
                                    //!< (and graphics for the raster flare path)
  /// Optional: the pNext chain the engine passed in VkDeviceCreateInfo (VkPhysicalDeviceFeatures2,
  /// VkPhysicalDeviceVulkan13Features, VkPhysicalDeviceSynchronization2Features,
  /// VkPhysicalDeviceMaintenance4Features, VkPhysicalDeviceDynamicRenderingFeatures, walked through
  /// pNext; other structs are skipped). When given, a feature counts as enabled only if a struct in
  /// the chain turns it on: adopt() refuses a chain without synchronization2 or maintenance4, and
  /// the raster flare path reports an Error when dynamicRendering is off. When null, glint checks
  /// that the physical device supports each feature and trusts the engine to have enabled it.
  const void* enabled_features = nullptr;
  /// As ContextOptions::frames_in_flight (1 to 16): the engine's frames in flight.
  uint32_t frames_in_flight = 3;
  /// Required: the device extensions the engine enabled on `device`, as it passed them in
  /// VkDeviceCreateInfo::ppEnabledExtensionNames / enabledExtensionCount (pass those two fields
  /// here). It must name VK_KHR_push_descriptor (VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME): glint pushes
  /// every kernel's descriptors with vkCmdPushDescriptorSetKHR and keeps no descriptor set, so the
  /// views and buffers a command buffer names may be destroyed once that command buffer is done.
  /// adopt() refuses a list without it (Error(invalid_argument) naming the extension). glint reads
  /// the list only during adopt().
  const char* const* enabled_extensions = nullptr;
  uint32_t enabled_extension_count = 0;
};

/// Facts about the device that kernels are tuned by (rule: chosen per device, never assumed).
struct DeviceInfo {
  std::string name;
  VkPhysicalDeviceType type{};
  uint32_t subgroup_size = 0;
  uint32_t max_shared_memory_bytes = 0;
  uint32_t max_workgroup_invocations = 0;
  uint32_t max_image_dimension_2d = 0;
  uint32_t sub_texel_precision_bits = 4;  //!< VkPhysicalDeviceLimits::subTexelPrecisionBits (at least 4)
  float timestamp_period_ns = 0.0f;       //!< nanoseconds per timestamp tick
  bool timestamps_supported = false;
};

namespace detail {
struct ContextState;
}

/// The Vulkan device glint works on. Move-only; effects keep a reference, so a Context must
/// outlive every effect made from it.
class Context {
 public:
  /// Creates an instance and a device of its own (Vulkan 1.3, one queue with compute).
  /// Throws Error(no_device) when no device matches options.device.
  static Context create(const ContextOptions& options = {});

  /// Wraps an engine's instance, physical device and device. Throws Error(invalid_argument) for
  /// null handles, a queue family without compute, api_version below 1.3 or an enabled_features
  /// chain without synchronization2 or maintenance4; Error(no_device) for a physical device below
  /// Vulkan 1.3 or (enabled_features null) without support for those features. Every message names
  /// the field or the feature (e.g. "VkPhysicalDeviceVulkan13Features::synchronization2").
  static Context adopt(const AdoptInfo& info);

  Context(Context&&) noexcept;
  Context& operator=(Context&&) noexcept;
  ~Context();

  VkInstance instance() const;
  VkPhysicalDevice physical_device() const;
  VkDevice device() const;
  uint32_t queue_family_index() const;
  const DeviceInfo& info() const;
  bool is_adopted() const;

  /// Standalone contexts only: records commands with `record`, submits them, waits for the
  /// queue and returns. For tools and tests; effects never call it. Throws in adopted mode.
  /// Safe from any thread: calls are serialized (one submission at a time); `record` may itself
  /// call run_once() on the same thread.
  void run_once(const std::function<void(VkCommandBuffer)>& record) const;

  /// Number of validation-layer messages (errors and warnings) seen since creation, and their
  /// text. Zero when validation is off.
  uint32_t validation_messages() const;
  std::vector<std::string> validation_log() const;

  /// Number of Vulkan objects glint has created through this context (pipelines, images,
  /// descriptor set layouts, ...). Tests use it to prove that recording a frame creates nothing.
  uint64_t objects_created() const;

  /// Frames. Call begin_frame() once per frame, before recording the frame's commands and after
  /// waiting for the fence of the frame frames_in_flight() frames earlier (the usual loop over
  /// frames_in_flight() command buffers and fences). It returns the new frame number (the first
  /// call returns 1; frame() is 0 before it). Effects that keep images per size note the frame of
  /// each record(); a size last recorded in frame L is destroyed by the effect's next record(),
  /// prepare() or release_unused() once frame() >= L + frames_in_flight(). Until then a size
  /// stays cached and costs nothing to record again. Without begin_frame() nothing recorded
  /// outside run_once() is ever assumed complete: an effect then keeps up to kMaxCachedSizes
  /// sizes and throws rather than destroy one (call mark_idle() after waiting for the device).
  /// Thread-safe; one thread should own the frame loop.
  uint64_t begin_frame() const;
  uint64_t frame() const;
  uint32_t frames_in_flight() const;
  /// The caller states that every command buffer recorded so far has completed or will never be
  /// submitted (after vkDeviceWaitIdle, or after waiting for every frame's fence, as before a
  /// swapchain resize). Advances frame() by frames_in_flight(), so that the effects' next
  /// record(), prepare() or release_unused() may destroy every size they do not use then.
  void mark_idle() const;
  /// Standalone contexts only: waits until the context's queue is idle (serialized with
  /// run_once()), then mark_idle(). Throws Error(invalid_argument) in adopted mode, where the
  /// engine owns the queues: wait there and call mark_idle().
  void wait_idle() const;

  /// Whether pipeline statistics are captured: ContextOptions::kernel_statistics was set and the
  /// device supports VK_KHR_pipeline_executable_properties (never for an adopted device).
  bool kernel_statistics_enabled() const;
  /// The driver's statistics of every compute pipeline this context has made so far, in kernel
  /// order; empty unless kernel_statistics_enabled().
  std::vector<KernelStatistics> kernel_statistics() const;

  detail::ContextState& state() const { return *state_; }

 private:
  explicit Context(std::unique_ptr<detail::ContextState> state);
  std::unique_ptr<detail::ContextState> state_;
};

/// Lists the Vulkan physical devices (creates and destroys a temporary instance).
std::vector<DeviceDescription> list_devices();

/// Storage precision of an effect's intermediate images.
enum class Precision : uint32_t {
  fp16 = 0,  //!< RGBA16F intermediates (default)
  fp32 = 1,  //!< RGBA32F intermediates
};

/// Size of one pyramid level.
struct LevelSize {
  uint32_t width = 0;
  uint32_t height = 0;
};

/// A view of a caller's 2D image that an effect reads or writes. The caller keeps ownership.
/// `layout`, `stage` and `access` describe the caller's last use of the image, so the effect can
/// write the right barrier; after record() they describe the effect's last use, which the caller's
/// next barrier starts from.
///
/// Array images: `view` is a 2D view (VK_IMAGE_VIEW_TYPE_2D) of the one layer `base_array_layer`;
/// effects transition that layer alone and leave every other layer as it was. `layer_count` must be
/// 1 (effects refuse others by name); the state fields describe that layer.
struct Image {
  VkImage image = VK_NULL_HANDLE;
  VkImageView view = VK_NULL_HANDLE;  //!< a 2D view of mip 0 of layer base_array_layer; colour aspect, or
                                      //!< depth aspect alone for a depth image (HiZPyramid, LightCuller)
  VkFormat format = VK_FORMAT_UNDEFINED;
  VkExtent2D extent{0, 0};
  VkImageUsageFlags usage = 0;  //!< the usage the image was created with
  VkImageLayout layout = VK_IMAGE_LAYOUT_UNDEFINED;
  VkPipelineStageFlags2 stage = VK_PIPELINE_STAGE_2_NONE;
  VkAccessFlags2 access = VK_ACCESS_2_NONE;
  uint32_t base_array_layer = 0;  //!< the layer `view` shows (0 for a non-array image)
  uint32_t layer_count = 1;       //!< layers `view` shows: effects accept 1
};

/// A view of a caller's buffer (or a range of it), with the caller's last use, like Image.
struct Buffer {
  VkBuffer buffer = VK_NULL_HANDLE;
  VkDeviceSize offset = 0;       //!< a multiple of minStorageBufferOffsetAlignment
  VkDeviceSize size = 0;         //!< bytes from offset that glint may use; required (glint cannot
                                 //!< query a VkBuffer's size, so 0 and VK_WHOLE_SIZE are refused)
  VkBufferUsageFlags usage = 0;  //!< the usage the buffer was created with
  VkPipelineStageFlags2 stage = VK_PIPELINE_STAGE_2_NONE;
  VkAccessFlags2 access = VK_ACCESS_2_NONE;
};

/// GPU timestamps around the stages an effect records. Pass one to an effect's record(); read
/// results() after the command buffer has completed.
class Profiler {
 public:
  /// capacity: the most marks per frame (1 to 4096).
  Profiler(const Context& context, uint32_t capacity = 64);
  Profiler(const Profiler&) = delete;
  Profiler& operator=(const Profiler&) = delete;
  ~Profiler();

  /// Resets the query pool; record once per frame before any mark().
  void reset(VkCommandBuffer cmd);
  /// Writes a timestamp once all earlier commands are done; `label` names the work since the
  /// previous mark (the first mark only starts the clock). Allocates nothing for labels of up to
  /// kLabelBytes characters (their storage is made by the constructor).
  void mark(VkCommandBuffer cmd, std::string_view label);
  static constexpr size_t kLabelBytes = 64;

  struct Stage {
    std::string label;
    double ms = 0.0;
  };
  /// The time between consecutive marks. Waits for the query results (call after the frame's
  /// fence). Empty if timestamps are not supported.
  std::vector<Stage> results() const;
  /// Milliseconds from the first to the last mark.
  double total_ms() const;

 private:
  const Context* context_;
  VkQueryPool pool_ = VK_NULL_HANDLE;
  uint32_t capacity_;
  uint32_t marks_ = 0;
  std::vector<std::string> labels_;
};

}  // namespace glint
