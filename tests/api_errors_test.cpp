// Bad input at every public entry point, as one table: each row
// calls one entry point with one bad argument, and must throw glint::Error with the expected code
// and a message naming the parameter and what is accepted, having recorded no command, created no
// Vulkan object and left the images' and buffers' state fields as they were. Then memory: a
// thousand resizes and repeated contexts must not grow the process or leave Vulkan objects behind.
//
// "Recorded nothing" is checked through detail::recorded_commands(): every vkCmd* call the library
// makes goes through Barriers::flush, ComputePipeline::dispatch or Profiler, which count (Vulkan
// cannot tell how many commands a command buffer holds). The command buffer is also submitted, and
// the poisoned output read back: a recorded dispatch would have written it.
//
// A new effect joins by adding its rows to api_cases() (configs: every field out of range and NaN;
// images/buffers: format, usage, zero size, above the device maximum, mismatched extents).
#include <glint/bloom.h>
#include <glint/blur.h>
#include <glint/lod.h>
#include <glint/occlusion.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "core/barriers.h"
#include "core/context_state.h"
#include "support/environment.h"
#include "support/gpu_test.h"
#include "support/transfer.h"

namespace glint::test {
namespace {

constexpr VkFormat kF16 = VK_FORMAT_R16G16B16A16_SFLOAT;
const float kNaN = std::numeric_limits<float>::quiet_NaN();

class ApiErrorsTest : public GpuTest {};

// The resources every row may use; rows copy the views they pass, so state changes are visible.
struct Fixture {
  detail::OwnedImage in = make_image(random_hdr(32, 24, 3), kF16);
  detail::OwnedImage out = make_poisoned({32, 24}, kF16);
  detail::OwnedImage other_size = make_poisoned({24, 32}, kF16);
  detail::OwnedImage unorm{context(), {32, 24}, VK_FORMAT_R8G8B8A8_UNORM, detail::kToolImageUsage};
  detail::OwnedImage no_storage{
      context(), {32, 24}, kF16, VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT};
  detail::OwnedImage no_sampled{
      context(), {32, 24}, kF16, VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT};
  detail::OwnedBuffer queries{context(), 64 * sizeof(LodQuery), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, false};
  detail::OwnedBuffer levels{context(), 64 * sizeof(float), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, false};
  Bloom bloom{context()};
  BlurPyramid pyramid{context()};
  GaussianBlur gauss{context()};
  LodBatch lod{context()};

  Buffer buffer(const detail::OwnedBuffer& b) const {
    return Buffer{b.buffer(),      0, b.size(), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, VK_PIPELINE_STAGE_2_NONE,
                  VK_ACCESS_2_NONE};
  }
};

struct ApiCase {
  std::string entry;                 //!< the entry point and what is wrong
  ErrorCode code;                    //!< the expected code
  std::vector<std::string> message;  //!< substrings the message must contain
  std::function<void(Fixture&, VkCommandBuffer, std::vector<Image*>&, std::vector<Buffer*>&)> call;
};

std::vector<ApiCase> api_cases() {
  std::vector<ApiCase> cases;
  const uint32_t max_dim = context().info().max_image_dimension_2d;

  // BloomConfig: each field out of range on each side and NaN, through the three entry points
  // that take a config.
  struct Field {
    const char* name;
    std::function<void(BloomConfig&)> set;
  };
  const std::vector<Field> bloom_fields = {
      {"threshold", [](BloomConfig& c) { c.threshold = -1.0f; }},
      {"threshold", [](BloomConfig& c) { c.threshold = 70000.0f; }},
      {"threshold", [](BloomConfig& c) { c.threshold = kNaN; }},
      {"soft_knee", [](BloomConfig& c) { c.soft_knee = -0.1f; }},
      {"soft_knee", [](BloomConfig& c) { c.soft_knee = 1.5f; }},
      {"soft_knee", [](BloomConfig& c) { c.soft_knee = kNaN; }},
      {"intensity", [](BloomConfig& c) { c.intensity = -0.1f; }},
      {"intensity", [](BloomConfig& c) { c.intensity = 101.0f; }},
      {"intensity", [](BloomConfig& c) { c.intensity = INFINITY; }},
      {"intensity", [](BloomConfig& c) { c.intensity = kNaN; }},
      {"iterations", [](BloomConfig& c) { c.iterations = 0; }},
      {"iterations", [](BloomConfig& c) { c.iterations = 9; }},
      {"radius", [](BloomConfig& c) { c.radius = 0.2f; }},
      {"radius", [](BloomConfig& c) { c.radius = 4.5f; }},
      {"radius", [](BloomConfig& c) { c.radius = kNaN; }},
      {"max_brightness", [](BloomConfig& c) { c.max_brightness = 0.0f; }},
      {"max_brightness", [](BloomConfig& c) { c.max_brightness = 9000.0f; }},
      {"max_brightness", [](BloomConfig& c) { c.max_brightness = kNaN; }},
      {"firefly_guard", [](BloomConfig& c) { c.firefly_guard = static_cast<FireflyGuard>(3); }},
      {"level0_height", [](BloomConfig& c) { c.level0_height = 4; }},
      {"level0_height", [](BloomConfig& c) { c.level0_height = 20000; }},
      {"filter", [](BloomConfig& c) { c.filter = static_cast<BloomFilter>(3); }},
      {"precision", [](BloomConfig& c) { c.precision = static_cast<Precision>(2); }},
  };
  for (const Field& f : bloom_fields) {
    BloomConfig bad;
    f.set(bad);
    const std::vector<std::string> msg = {std::string("BloomConfig::") + f.name, "accepted"};
    cases.push_back({std::string("Bloom(config) ") + f.name, ErrorCode::invalid_argument, msg,
                     [bad](Fixture&, VkCommandBuffer, auto&, auto&) { Bloom b(context(), bad); }});
    cases.push_back({std::string("Bloom::set_config ") + f.name, ErrorCode::invalid_argument, msg,
                     [bad](Fixture& fx, VkCommandBuffer, auto&, auto&) { fx.bloom.set_config(bad); }});
    cases.push_back({std::string("BloomConfig::validate ") + f.name, ErrorCode::invalid_argument, msg,
                     [bad](Fixture&, VkCommandBuffer, auto&, auto&) { bad.validate(); }});
  }

  // Bloom::prepare sizes.
  for (VkExtent2D e :
       {VkExtent2D{0, 16}, VkExtent2D{16, 0}, VkExtent2D{max_dim + 1, 16}, VkExtent2D{16, max_dim + 1}}) {
    cases.push_back({"Bloom::prepare " + std::to_string(e.width) + "x" + std::to_string(e.height),
                     ErrorCode::unsupported_size,
                     {"Bloom::prepare", "accepted 1 to " + std::to_string(max_dim)},
                     [e](Fixture& fx, VkCommandBuffer, auto&, auto&) { fx.bloom.prepare(e); }});
    cases.push_back(
        {"Bloom::prepare(extent, format) " + std::to_string(e.width) + "x" + std::to_string(e.height),
         ErrorCode::unsupported_size,
         {"Bloom::prepare", "accepted 1 to " + std::to_string(max_dim)},
         [e](Fixture& fx, VkCommandBuffer, auto&, auto&) { fx.bloom.prepare(e, VK_FORMAT_R16G16B16A16_SFLOAT); }});
  }
  // An output format no kernel stores (not a float colour format), refused before anything is made.
  cases.push_back({"Bloom::prepare(extent, format) R8G8B8A8_UNORM",
                   ErrorCode::unsupported_format,
                   {"Bloom::prepare: output format is VK_FORMAT_R8G8B8A8_UNORM", "accepted"},
                   [](Fixture& fx, VkCommandBuffer, auto&, auto&) {
                     fx.bloom.prepare({40, 24}, VK_FORMAT_R8G8B8A8_UNORM);
                   }});

  // Bloom::record images. Each row edits copies of the fixture's image views.
  using Edit = std::function<void(Fixture&, Image & in, Image & out)>;
  struct ImageRow {
    const char* what;
    ErrorCode code;
    std::vector<std::string> message;
    Edit edit;
  };
  const std::vector<ImageRow> image_rows = {
      {"unorm input",
       ErrorCode::unsupported_format,
       {"input format", "accepted VK_FORMAT_R16G16B16A16_SFLOAT"},
       [](Fixture& fx, Image& in, Image&) { in = fx.unorm.state; }},
      {"unorm output",
       ErrorCode::unsupported_format,
       {"output format", "accepted"},
       [](Fixture& fx, Image&, Image& out) { out = fx.unorm.state; }},
      {"input without SAMPLED",
       ErrorCode::missing_usage,
       {"input", "VK_IMAGE_USAGE_SAMPLED_BIT"},
       [](Fixture& fx, Image& in, Image&) { in = fx.no_sampled.state; }},
      {"output without STORAGE",
       ErrorCode::missing_usage,
       {"output", "VK_IMAGE_USAGE_STORAGE_BIT"},
       [](Fixture& fx, Image&, Image& out) { out = fx.no_storage.state; }},
      {"zero-width input",
       ErrorCode::unsupported_size,
       {"input extent", "accepted 1 to"},
       [](Fixture&, Image& in, Image&) { in.extent.width = 0; }},
      {"zero-height output",
       ErrorCode::unsupported_size,
       {"output extent", "accepted 1 to"},
       [](Fixture&, Image&, Image& out) { out.extent.height = 0; }},
      {"input above the device maximum",
       ErrorCode::unsupported_size,
       {"input extent", "accepted 1 to"},
       [max_dim](Fixture&, Image& in, Image& out) {
         in.extent = out.extent = {max_dim + 1, 24};
       }},
      {"mismatched extents",
       ErrorCode::invalid_argument,
       {"output extent 24x32", "input extent 32x24"},
       [](Fixture& fx, Image&, Image& out) { out = fx.other_size.state; }},
      {"null input image",
       ErrorCode::invalid_argument,
       {"input image and view"},
       [](Fixture&, Image& in, Image&) { in.image = VK_NULL_HANDLE; }},
      {"null output view",
       ErrorCode::invalid_argument,
       {"output image and view"},
       [](Fixture&, Image&, Image& out) { out.view = VK_NULL_HANDLE; }},
      {"in place with two formats",
       ErrorCode::invalid_argument,
       {"same format"},
       [](Fixture& fx, Image& in, Image& out) {
         out = fx.out.state;
         in = out;
         in.format = VK_FORMAT_R32G32B32A32_SFLOAT;
       }},
  };
  for (const ImageRow& row : image_rows) {
    std::vector<std::string> msg = row.message;
    msg.insert(msg.begin(), "Bloom::record");
    cases.push_back({std::string("Bloom::record ") + row.what, row.code, msg,
                     [edit = row.edit](Fixture& fx, VkCommandBuffer cmd, std::vector<Image*>& images, auto&) {
                       edit(fx, *images[0], *images[1]);
                       fx.bloom.record(cmd, *images[0], *images[1]);
                     }});
  }

  // Blur: config fields, prepare sizes and images, as for bloom. In-place rows do not
  // apply (GaussianBlur refuses input == output with its own row; BlurPyramid writes its own
  // levels).
  struct PyramidField {
    const char* name;
    std::function<void(BlurPyramidConfig&)> set;
  };
  const std::vector<PyramidField> pyramid_fields = {
      {"sigma_texels[0]", [](BlurPyramidConfig& c) { c.sigma_texels[0] = 0.1f; }},
      {"sigma_texels[1]", [](BlurPyramidConfig& c) { c.sigma_texels[1] = 5.0f; }},
      {"sigma_texels[2]", [](BlurPyramidConfig& c) { c.sigma_texels[2] = kNaN; }},
      {"precision", [](BlurPyramidConfig& c) { c.precision = static_cast<Precision>(2); }},
  };
  for (const PyramidField& f : pyramid_fields) {
    BlurPyramidConfig bad;
    f.set(bad);
    const std::vector<std::string> msg = {std::string("BlurPyramidConfig::") + f.name, "accepted"};
    cases.push_back({std::string("BlurPyramid(config) ") + f.name, ErrorCode::invalid_argument, msg,
                     [bad](Fixture&, VkCommandBuffer, auto&, auto&) { BlurPyramid b(context(), bad); }});
    cases.push_back({std::string("BlurPyramid::set_config ") + f.name, ErrorCode::invalid_argument, msg,
                     [bad](Fixture& fx, VkCommandBuffer, auto&, auto&) { fx.pyramid.set_config(bad); }});
  }
  struct GaussField {
    const char* name;
    std::function<void(GaussianBlurConfig&)> set;
  };
  const std::vector<GaussField> gauss_fields = {
      {"sigma_px", [](GaussianBlurConfig& c) { c.sigma_px = 0.4f; }},
      {"sigma_px", [](GaussianBlurConfig& c) { c.sigma_px = 65.0f; }},
      {"sigma_px", [](GaussianBlurConfig& c) { c.sigma_px = kNaN; }},
      {"max_relative_error", [](GaussianBlurConfig& c) { c.max_relative_error = 0.0f; }},
      {"max_relative_error", [](GaussianBlurConfig& c) { c.max_relative_error = 2.0f; }},
      {"max_relative_error", [](GaussianBlurConfig& c) { c.max_relative_error = kNaN; }},
      {"method", [](GaussianBlurConfig& c) { c.method = static_cast<BlurMethod>(4); }},
      {"precision", [](GaussianBlurConfig& c) { c.precision = static_cast<Precision>(2); }},
      {"linear_sampling", [](GaussianBlurConfig& c) { c.linear_sampling = true; }},  // needs separable
  };
  for (const GaussField& f : gauss_fields) {
    GaussianBlurConfig bad;
    f.set(bad);
    const std::vector<std::string> msg = {std::string("GaussianBlurConfig::") + f.name, "accepted"};
    const std::vector<std::string> linear_msg = {"GaussianBlurConfig::linear_sampling", "needs method separable"};
    const auto& m = std::string(f.name) == "linear_sampling" ? linear_msg : msg;
    cases.push_back({std::string("GaussianBlur(config) ") + f.name, ErrorCode::invalid_argument, m,
                     [bad](Fixture&, VkCommandBuffer, auto&, auto&) { GaussianBlur b(context(), bad); }});
    cases.push_back({std::string("GaussianBlur::set_config ") + f.name, ErrorCode::invalid_argument, m,
                     [bad](Fixture& fx, VkCommandBuffer, auto&, auto&) { fx.gauss.set_config(bad); }});
  }
  for (VkExtent2D e :
       {VkExtent2D{0, 16}, VkExtent2D{16, 0}, VkExtent2D{max_dim + 1, 16}, VkExtent2D{16, max_dim + 1}}) {
    const std::string size = std::to_string(e.width) + "x" + std::to_string(e.height);
    const std::string range = "accepted 1 to " + std::to_string(max_dim);
    cases.push_back({"BlurPyramid::prepare " + size,
                     ErrorCode::unsupported_size,
                     {"BlurPyramid::prepare", range},
                     [e](Fixture& fx, VkCommandBuffer, auto&, auto&) { fx.pyramid.prepare(e); }});
    cases.push_back({"GaussianBlur::prepare " + size,
                     ErrorCode::unsupported_size,
                     {"GaussianBlur::prepare", range},
                     [e](Fixture& fx, VkCommandBuffer, auto&, auto&) { fx.gauss.prepare(e); }});
    cases.push_back(
        {"GaussianBlur::prepare(extent, format) " + size,
         ErrorCode::unsupported_size,
         {"GaussianBlur::prepare", range},
         [e](Fixture& fx, VkCommandBuffer, auto&, auto&) { fx.gauss.prepare(e, VK_FORMAT_R16G16B16A16_SFLOAT); }});
  }
  cases.push_back({"GaussianBlur::prepare(extent, format) R8G8B8A8_UNORM",
                   ErrorCode::unsupported_format,
                   {"GaussianBlur::prepare: output format is VK_FORMAT_R8G8B8A8_UNORM", "accepted"},
                   [](Fixture& fx, VkCommandBuffer, auto&, auto&) {
                     fx.gauss.prepare({40, 24}, VK_FORMAT_R8G8B8A8_UNORM);
                   }});
  for (const ImageRow& row : image_rows) {
    const std::string what = row.what;
    if (what == "in place with two formats") continue;
    std::vector<std::string> msg = row.message;
    msg.insert(msg.begin(), "GaussianBlur::record");
    cases.push_back({"GaussianBlur::record " + what, row.code, msg,
                     [edit = row.edit](Fixture& fx, VkCommandBuffer cmd, std::vector<Image*>& images, auto&) {
                       edit(fx, *images[0], *images[1]);
                       fx.gauss.record(cmd, *images[0], *images[1]);
                     }});
    if (what.rfind("input", 0) == 0 || what.rfind("unorm input", 0) == 0 || what.rfind("zero-width input", 0) == 0 ||
        what.rfind("null input", 0) == 0) {
      std::vector<std::string> pmsg = row.message;
      pmsg.insert(pmsg.begin(), "BlurPyramid::record");
      cases.push_back({"BlurPyramid::record " + what, row.code, pmsg,
                       [edit = row.edit](Fixture& fx, VkCommandBuffer cmd, std::vector<Image*>& images, auto&) {
                         edit(fx, *images[0], *images[1]);
                         fx.pyramid.record(cmd, *images[0]);
                       }});
    }
  }
  cases.push_back({"GaussianBlur::record in place",
                   ErrorCode::invalid_argument,
                   {"GaussianBlur::record", "different images"},
                   [](Fixture& fx, VkCommandBuffer cmd, std::vector<Image*>& images, auto&) {
                     fx.gauss.record(cmd, *images[0], *images[0]);
                   }});

  // A null command buffer and image layouts outside the VkImageLayout enumeration.
  cases.push_back({"Bloom::record null command buffer",
                   ErrorCode::invalid_argument,
                   {"Bloom::record", "command buffer is null"},
                   [](Fixture& fx, VkCommandBuffer, std::vector<Image*>& images, auto&) {
                     fx.bloom.record(VK_NULL_HANDLE, *images[0], *images[1]);
                   }});
  cases.push_back({"BlurPyramid::record null command buffer",
                   ErrorCode::invalid_argument,
                   {"BlurPyramid::record", "command buffer is null"},
                   [](Fixture& fx, VkCommandBuffer, std::vector<Image*>& images, auto&) {
                     fx.pyramid.record(VK_NULL_HANDLE, *images[0]);
                   }});
  cases.push_back({"GaussianBlur::record null command buffer",
                   ErrorCode::invalid_argument,
                   {"GaussianBlur::record", "command buffer is null"},
                   [](Fixture& fx, VkCommandBuffer, std::vector<Image*>& images, auto&) {
                     fx.gauss.record(VK_NULL_HANDLE, *images[0], *images[1]);
                   }});
  cases.push_back({"LodBatch::record null command buffer",
                   ErrorCode::invalid_argument,
                   {"LodBatch::record", "command buffer is null"},
                   [](Fixture& fx, VkCommandBuffer, auto&, std::vector<Buffer*>& b) {
                     fx.lod.record(VK_NULL_HANDLE, *b[0], *b[1], 16, LodAtlasConfig{});
                   }});
  cases.push_back({"Bloom::record input layout 12345",
                   ErrorCode::invalid_argument,
                   {"Bloom::record", "input Image::layout = 12345", "accepts"},
                   [](Fixture& fx, VkCommandBuffer cmd, std::vector<Image*>& images, auto&) {
                     images[0]->layout = static_cast<VkImageLayout>(12345);
                     fx.bloom.record(cmd, *images[0], *images[1]);
                   }});
  cases.push_back({"GaussianBlur::record output layout PREINITIALIZED",
                   ErrorCode::invalid_argument,
                   {"GaussianBlur::record", "output Image::layout = VK_IMAGE_LAYOUT_PREINITIALIZED"},
                   [](Fixture& fx, VkCommandBuffer cmd, std::vector<Image*>& images, auto&) {
                     images[1]->layout = VK_IMAGE_LAYOUT_PREINITIALIZED;
                     fx.gauss.record(cmd, *images[0], *images[1]);
                   }});

  // LodAtlasConfig fields, through validate(), lod_level() and LodBatch::record.
  struct LodField {
    const char* name;
    std::function<void(LodAtlasConfig&)> set;
  };
  const std::vector<LodField> lod_fields = {
      {"atlas_width", [](LodAtlasConfig& a) { a.atlas_width = 0; }},
      {"atlas_width", [](LodAtlasConfig& a) { a.atlas_width = 65537; }},
      {"atlas_height", [](LodAtlasConfig& a) { a.atlas_height = 0; }},
      {"atlas_height", [](LodAtlasConfig& a) { a.atlas_height = 1u << 20; }},
      {"levels", [](LodAtlasConfig& a) { a.levels = 0; }},
      {"levels", [](LodAtlasConfig& a) { a.levels = 18; }},
      {"bias", [](LodAtlasConfig& a) { a.bias = -16.5f; }},
      {"bias", [](LodAtlasConfig& a) { a.bias = 17.0f; }},
      {"bias", [](LodAtlasConfig& a) { a.bias = kNaN; }},
      {"max_anisotropy", [](LodAtlasConfig& a) { a.max_anisotropy = 0.5f; }},
      {"max_anisotropy", [](LodAtlasConfig& a) { a.max_anisotropy = 65.0f; }},
      {"max_anisotropy", [](LodAtlasConfig& a) { a.max_anisotropy = kNaN; }},
      {"padding_texels", [](LodAtlasConfig& a) { a.padding_texels = 70000.0f; }},
      {"padding_texels", [](LodAtlasConfig& a) { a.padding_texels = kNaN; }},
  };
  for (const LodField& f : lod_fields) {
    LodAtlasConfig bad;
    f.set(bad);
    const std::vector<std::string> msg = {std::string("LodAtlasConfig::") + f.name, "accepted"};
    cases.push_back({std::string("LodAtlasConfig::validate ") + f.name, ErrorCode::invalid_argument, msg,
                     [bad](Fixture&, VkCommandBuffer, auto&, auto&) { bad.validate(); }});
    cases.push_back({std::string("lod_level ") + f.name, ErrorCode::invalid_argument, msg,
                     [bad](Fixture&, VkCommandBuffer, auto&, auto&) { (void)lod_level(LodQuery{}, bad); }});
    cases.push_back({std::string("LodBatch::record ") + f.name, ErrorCode::invalid_argument, msg,
                     [bad](Fixture& fx, VkCommandBuffer cmd, auto&, std::vector<Buffer*>& b) {
                       fx.lod.record(cmd, *b[0], *b[1], 16, bad);
                     }});
  }

  // LodBatch::record buffers and counts.
  using BufferEdit = std::function<void(Buffer & q, Buffer & l, uint32_t & count)>;
  struct BufferRow {
    const char* what;
    ErrorCode code;
    std::vector<std::string> message;
    BufferEdit edit;
  };
  const std::vector<BufferRow> buffer_rows = {
      {"null queries",
       ErrorCode::invalid_argument,
       {"queries buffer is null"},
       [](Buffer& q, Buffer&, uint32_t&) { q.buffer = VK_NULL_HANDLE; }},
      {"null levels",
       ErrorCode::invalid_argument,
       {"levels buffer is null"},
       [](Buffer&, Buffer& l, uint32_t&) { l.buffer = VK_NULL_HANDLE; }},
      {"queries too small",
       ErrorCode::invalid_argument,
       {"queries buffer", "accepted at least 2048"},
       [](Buffer& q, Buffer&, uint32_t& n) {
         q.size = 100;
         n = 64;
       }},
      {"levels too small",
       ErrorCode::invalid_argument,
       {"levels buffer", "accepted at least 256"},
       [](Buffer&, Buffer& l, uint32_t& n) {
         l.size = 255;
         n = 64;
       }},
      {"queries without STORAGE_BUFFER",
       ErrorCode::missing_usage,
       {"queries", "VK_BUFFER_USAGE_STORAGE_BUFFER_BIT"},
       [](Buffer& q, Buffer&, uint32_t&) { q.usage = VK_BUFFER_USAGE_TRANSFER_SRC_BIT; }},
      {"levels without STORAGE_BUFFER",
       ErrorCode::missing_usage,
       {"levels", "VK_BUFFER_USAGE_STORAGE_BUFFER_BIT"},
       [](Buffer&, Buffer& l, uint32_t&) { l.usage = 0; }},
      {"queries size VK_WHOLE_SIZE",
       ErrorCode::invalid_argument,
       {"queries Buffer::size = VK_WHOLE_SIZE", "at least 512"},
       [](Buffer& q, Buffer&, uint32_t&) { q.size = VK_WHOLE_SIZE; }},
      {"levels size 0",
       ErrorCode::invalid_argument,
       {"levels Buffer::size = 0", "at least 64"},
       [](Buffer&, Buffer& l, uint32_t&) { l.size = 0; }},
      {"100000 queries in a 512-byte buffer",
       ErrorCode::invalid_argument,
       {"queries buffer holds 512 bytes", "accepted at least 3200000"},
       [](Buffer& q, Buffer& l, uint32_t& n) {
         q.size = l.size = 512;
         n = 100000;
       }},
      {"misaligned offset",
       ErrorCode::invalid_argument,
       {"levels buffer offset = 2", "multiple of 4"},
       [](Buffer&, Buffer& l, uint32_t&) {
         l.offset = 2;
         l.size = 128;
       }},
      {"count above the maximum",
       ErrorCode::invalid_argument,
       {"count = 4194241", "accepted 0 to 4194240"},
       [](Buffer& q, Buffer& l, uint32_t& n) {
         q.size = l.size = VK_WHOLE_SIZE;
         n = 65535u * 64u + 1u;
       }},
  };
  for (const BufferRow& row : buffer_rows) {
    std::vector<std::string> msg = row.message;
    msg.insert(msg.begin(), "LodBatch::record");
    cases.push_back({std::string("LodBatch::record ") + row.what, row.code, msg,
                     [edit = row.edit](Fixture& fx, VkCommandBuffer cmd, auto&, std::vector<Buffer*>& b) {
                       uint32_t count = 16;
                       edit(*b[0], *b[1], count);
                       fx.lod.record(cmd, *b[0], *b[1], count, LodAtlasConfig{});
                     }});
  }

  // Context::adopt: the engine's device extension list must name VK_KHR_push_descriptor (every
  // kernel's descriptors are pushed); the test context's device has it, so only the list is wrong.
  cases.push_back({"Context::adopt without an extension list",
                   ErrorCode::invalid_argument,
                   {"VK_KHR_push_descriptor is not in AdoptInfo::enabled_extensions"},
                   [](Fixture&, VkCommandBuffer, auto&, auto&) { Context::adopt(adopt_info_of_context()); }});
  cases.push_back({"Context::adopt with a list that lacks VK_KHR_push_descriptor",
                   ErrorCode::invalid_argument,
                   {"VK_KHR_push_descriptor is not in AdoptInfo::enabled_extensions", "1 names given"},
                   [](Fixture&, VkCommandBuffer, auto&, auto&) {
                     static const char* const other[] = {VK_KHR_SWAPCHAIN_EXTENSION_NAME};
                     AdoptInfo a = adopt_info_of_context();
                     a.enabled_extensions = other;
                     a.enabled_extension_count = 1;
                     Context::adopt(a);
                   }});
  cases.push_back({"Context::adopt with a count and a null list",
                   ErrorCode::invalid_argument,
                   {"AdoptInfo::enabled_extension_count = 3", "null AdoptInfo::enabled_extensions"},
                   [](Fixture&, VkCommandBuffer, auto&, auto&) {
                     AdoptInfo a = adopt_info_of_context();
                     a.enabled_extension_count = 3;
                     Context::adopt(a);
                   }});
  return cases;
}

bool same_state(const Image& a, const Image& b) {
  return a.image == b.image && a.view == b.view && a.format == b.format && a.extent.width == b.extent.width &&
         a.extent.height == b.extent.height && a.layout == b.layout && a.stage == b.stage && a.access == b.access;
}
bool same_state(const Buffer& a, const Buffer& b) {
  return a.buffer == b.buffer && a.offset == b.offset && a.size == b.size && a.stage == b.stage && a.access == b.access;
}

TEST_F(ApiErrorsTest, EveryEntryPointRejectsBadInputAndRecordsNothing) {
  Fixture fx;
  fx.bloom.prepare({32, 24});  // so that a wrongly accepted record would create nothing new either
  const auto cases = api_cases();
  EXPECT_GT(cases.size(), 100u);
  for (const ApiCase& c : cases) {
    Image in = fx.in.state, out = fx.out.state;
    Buffer q = fx.buffer(fx.queries), l = fx.buffer(fx.levels);
    std::vector<Image*> images = {&in, &out};
    std::vector<Buffer*> buffers = {&q, &l};
    const uint64_t commands = detail::recorded_commands();
    const uint64_t objects = context().objects_created();
    context().run_once([&](VkCommandBuffer cmd) {
      try {
        // The row edits the views first; what it passes is compared after the throw.
        c.call(fx, cmd, images, buffers);
        ADD_FAILURE() << c.entry << ": no error";
      } catch (const Error& e) {
        const std::string what = e.what();
        EXPECT_EQ(e.code(), c.code) << c.entry << ": " << what;
        for (const std::string& part : c.message) {
          EXPECT_NE(what.find(part), std::string::npos) << c.entry << ": '" << what << "' lacks '" << part << "'";
        }
        EXPECT_EQ(what.find('\n'), std::string::npos) << c.entry << ": one line";
      } catch (const std::exception& e) {
        ADD_FAILURE() << c.entry << ": not a glint::Error: " << e.what();
      }
    });
    EXPECT_EQ(detail::recorded_commands(), commands) << c.entry << ": recorded a command";
    EXPECT_EQ(context().objects_created(), objects) << c.entry << ": created a Vulkan object";
  }
  // The record() rows edit copies; the fixture's own images were never touched or written.
  const CpuImage after = detail::download(context(), fx.out.state);
  EXPECT_FALSE(all_finite(after));
  for (float v : after.rgba) ASSERT_TRUE(std::isnan(v)) << "the poisoned output was written";
}

// The edits above change the views before the call, so "state untouched" is checked here on rows
// whose views are otherwise valid: the state fields (layout, stage, access) after a throwing
// record() are exactly those before it.
TEST_F(ApiErrorsTest, AThrowingRecordLeavesTheStateFieldsAlone) {
  Fixture fx;
  Image in = fx.in.state, out = fx.other_size.state;  // mismatched extents: checked last
  const Image in0 = in, out0 = out;
  Buffer q = fx.buffer(fx.queries), l = fx.buffer(fx.levels);
  l.size = 4;  // too small for 16 queries
  const Buffer q0 = q, l0 = l;
  context().run_once([&](VkCommandBuffer cmd) {
    EXPECT_THROW(fx.bloom.record(cmd, in, out), Error);
    EXPECT_THROW(fx.lod.record(cmd, q, l, 16, LodAtlasConfig{}), Error);
  });
  EXPECT_TRUE(same_state(in, in0));
  EXPECT_TRUE(same_state(out, out0));
  EXPECT_TRUE(same_state(q, q0));
  EXPECT_TRUE(same_state(l, l0));
  // And the counter does move when something is recorded, so the table's check can fail.
  const uint64_t before = detail::recorded_commands();
  context().run_once([&](VkCommandBuffer cmd) {
    Image o = fx.out.state;
    fx.bloom.record(cmd, in, o);
  });
  EXPECT_GT(detail::recorded_commands(), before);
}

TEST_F(ApiErrorsTest, ZeroLodCountRecordsNothing) {
  Fixture fx;
  Buffer q = fx.buffer(fx.queries), l = fx.buffer(fx.levels);
  const uint64_t before = detail::recorded_commands();
  context().run_once([&](VkCommandBuffer cmd) { fx.lod.record(cmd, q, l, 0, LodAtlasConfig{}); });
  EXPECT_EQ(detail::recorded_commands(), before);
}

// ---- memory -----------------------------------------------------------------------------------

// The memory the leak bounds below are checked on. AddressSanitizer keeps freed memory in
// quarantine (256 MiB by default), so RSS grows by design in the ASan build; there the bounds are
// checked on the bytes currently allocated through ASan's allocator instead, which every malloc of
// the process goes through (the uninstrumented loader, driver and validation layer included, and
// lavapipe's device memory, which it mallocs): exact live heap, quarantine excluded. So `./glint.sh
// test`, which runs only the ASan build, asserts the bounds as well.
#if defined(__SANITIZE_ADDRESS__)
#define GLINT_TEST_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define GLINT_TEST_ASAN 1
#endif
#endif
#if defined(GLINT_TEST_ASAN)
// From sanitizer/allocator_interface.h (shipped with clang's runtime, not with GCC's headers); an
// extern "C" declaration names the same function in any namespace.
extern "C" size_t __sanitizer_get_current_allocated_bytes();
const char* const kMemoryMeasure = "live heap (ASan allocator)";
uint64_t memory_in_use() { return __sanitizer_get_current_allocated_bytes(); }
#else
// Resident set size in bytes (/proc/self/statm, second field, in pages).
uint64_t rss_bytes() {
  FILE* f = std::fopen("/proc/self/statm", "r");
  unsigned long long size = 0, resident = 0;
  if (f) {
    if (std::fscanf(f, "%llu %llu", &size, &resident) != 2) resident = 0;
    std::fclose(f);
  }
  return resident * uint64_t(sysconf(_SC_PAGESIZE));
}
const char* const kMemoryMeasure = "RSS";
uint64_t memory_in_use() { return rss_bytes(); }
#endif

ContextOptions validated() {
  ContextOptions o;
  o.validation = true;
  return tools::context_options_from_environment(o);
}

// The object tracker of the validation layer reports every object still alive when a device is
// destroyed. Proof that it does (so the two tests below can fail): leak one buffer on purpose.
TEST(ApiMemory, ObjectTrackerReportsALeakAtContextDestruction) {
  const uint64_t before = detail::validation_messages_all_contexts();
  {
    Context ctx = Context::create(validated());
    VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    info.size = 256;
    info.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
    VkBuffer leaked = VK_NULL_HANDLE;
    ASSERT_EQ(vkCreateBuffer(ctx.device(), &info, nullptr, &leaked), VK_SUCCESS);
  }
  EXPECT_GT(detail::validation_messages_all_contexts(), before);
}

// 1000 prepare() calls cycling through 40 sizes, more than the kMaxCachedSizes an effect keeps, so
// that from the 33rd on each one destroys the least recently used size and makes a new one (bloom
// with and without level0_height's pre-levels, the blur pyramid, the Gaussian blur's pyramid
// method); the Hi-Z pyramid, whose size is part of its config, is made 1000 times instead (its
// kernels compile once per context: before they were shared, each make grew lavapipe by ~4 MB).
// Leaked Vulkan objects (images, memory, views, pools) are caught by the object tracker when the
// context goes; RSS catches host-side growth (descriptor-set maps, vectors). lavapipe's device
// memory counts in RSS only once written, so RSS alone would not see a leaked, never-used pyramid.
TEST(ApiMemory, AThousandResizesDoNotGrowMemory) {
  const uint64_t messages = detail::validation_messages_all_contexts();
  uint64_t warm = 0, end = 0;
  {
    Context ctx = Context::create(validated());
    Bloom bloom(ctx);
    BloomConfig stepped;
    stepped.level0_height = 40;
    stepped.filter = BloomFilter::gauss9;
    Bloom bloom_stepped(ctx, stepped);
    BlurPyramid pyramid(ctx);
    GaussianBlurConfig gauss_config;
    gauss_config.method = BlurMethod::pyramid;
    gauss_config.sigma_px = 6.0f;
    GaussianBlur gauss(ctx, gauss_config);
    for (int i = 0; i < 1000; ++i) {
      static_assert(kMaxCachedSizes < 40);
      const VkExtent2D e{200 + 2 * static_cast<uint32_t>(i % 40), 100 + static_cast<uint32_t>(i % 40)};
      bloom.prepare(e);
      bloom_stepped.prepare(e);
      pyramid.prepare(e);
      gauss.prepare(e);
      HiZConfig hiz;
      hiz.extent = e;
      HiZPyramid made(ctx, hiz);
      if (i == 99) warm = memory_in_use();
    }
    EXPECT_EQ(bloom.cached_sizes(), kMaxCachedSizes);
    EXPECT_EQ(gauss.cached_sizes(), kMaxCachedSizes);
    end = memory_in_use();
  }
  EXPECT_LT(end, warm + (16u << 20)) << kMemoryMeasure << " grew from " << warm << " to " << end << " bytes";
  EXPECT_EQ(detail::validation_messages_all_contexts(), messages) << "objects left behind (see the log above)";
}

// An image larger than the device's maxResourceSize for its format is refused before
// vkCreateImage (creating it is invalid usage; lavapipe's 16384x16384 RGBA32F, 2^32 bytes, is one
// byte over its 2^32 - 1), with the bytes needed and the limit in the message.
TEST_F(ApiErrorsTest, AnImageOverMaxResourceSizeIsRefusedBeforeItIsCreated) {
  const uint32_t max_dim = context().info().max_image_dimension_2d;
  const VkFormat format = VK_FORMAT_R32G32B32A32_SFLOAT;
  VkImageFormatProperties props{};
  ASSERT_EQ(vkGetPhysicalDeviceImageFormatProperties(context().physical_device(), format, VK_IMAGE_TYPE_2D,
                                                     VK_IMAGE_TILING_OPTIMAL, detail::kToolImageUsage, 0, &props),
            VK_SUCCESS);
  const uint64_t bytes = uint64_t(max_dim) * max_dim * 16;
  if (bytes <= props.maxResourceSize) {
    GTEST_SKIP() << "the largest RGBA32F image (" << bytes << " bytes) fits maxResourceSize (" << props.maxResourceSize
                 << ") on this device";
  }
  const uint64_t objects = context().objects_created();
  try {
    detail::OwnedImage image(context(), {max_dim, max_dim}, format, detail::kToolImageUsage);
    FAIL() << "a " << bytes << "-byte image was made";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::unsupported_size);
    const std::string text = e.what();
    EXPECT_NE(text.find(std::to_string(bytes) + " bytes"), std::string::npos) << text;
    EXPECT_NE(text.find("maxResourceSize) is " + std::to_string(props.maxResourceSize)), std::string::npos) << text;
  }
  EXPECT_EQ(context().objects_created(), objects);
}

// Contexts made and destroyed over and over, each running a bloom and a LOD batch.
TEST(ApiMemory, RecreatingContextsDoesNotGrowMemory) {
  const uint64_t messages = detail::validation_messages_all_contexts();
  const CpuImage input = random_hdr(64, 48, 1);
  uint64_t warm = 0;
  for (int i = 0; i < 12; ++i) {
    Context ctx = Context::create(validated());
    Bloom bloom(ctx);
    LodBatch lod(ctx);
    detail::OwnedImage in(ctx, {64, 48}, kF16, detail::kToolImageUsage),
        out(ctx, {64, 48}, kF16, detail::kToolImageUsage);
    detail::upload(ctx, in.state, input);
    detail::OwnedBuffer qb(ctx, 64 * sizeof(LodQuery), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, false);
    detail::OwnedBuffer lb(ctx, 64 * sizeof(float), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, false);
    Buffer q{qb.buffer(), 0, qb.size(), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT};
    Buffer l{lb.buffer(), 0, lb.size(), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT};
    ctx.run_once([&](VkCommandBuffer cmd) {
      bloom.record(cmd, in.state, out.state);
      lod.record(cmd, q, l, 64, LodAtlasConfig{});
    });
    EXPECT_EQ(ctx.validation_messages(), 0u);
    if (i == 3) warm = memory_in_use();
  }
  const uint64_t end = memory_in_use();
  EXPECT_LT(end, warm + (24u << 20)) << kMemoryMeasure << " grew from " << warm << " to " << end << " bytes";
  EXPECT_EQ(detail::validation_messages_all_contexts(), messages) << "objects left behind (see the log above)";
}

}  // namespace
}  // namespace glint::test
