// LOD driver: the CPU twin (same source as the kernels) and the batch kernel.
#include <glint/lod.h>

#include <cstddef>

#include "core/barriers.h"
#include "core/check.h"
#include "core/pipeline.h"
#include "lod/lod_math.h"

namespace glint {

using detail::check_range;
using detail::concat;

static_assert(sizeof(LodQuery) == sizeof(GlintLodQuery) && sizeof(LodQuery) == 32);
static_assert(offsetof(LodQuery, tex_w) == offsetof(GlintLodQuery, tex_w));
static_assert(offsetof(LodQuery, off_y) == offsetof(GlintLodQuery, off_y));
static_assert(sizeof(GlintLodAtlas) == 32);

namespace {

struct LodPush {  // src/lod/shaders/lod_batch.comp and lod_probe.comp push constants
  GlintLodAtlas atlas;
  uint32_t count;
};
static_assert(sizeof(LodPush) == 36);

GlintLodQuery to_glsl(const LodQuery& q) {
  return {q.dudx, q.dvdx, q.dudy, q.dvdy, q.tex_w, q.tex_h, q.off_x, q.off_y};
}

GlintLodAtlas to_glsl_atlas(const LodAtlasConfig& a) {
  GlintLodAtlas g{};
  g.atlas_w = static_cast<float>(a.atlas_width);
  g.atlas_h = static_cast<float>(a.atlas_height);
  g.levels = static_cast<float>(a.levels);
  g.bias = a.bias;
  g.max_aniso = a.max_anisotropy;
  g.padding = a.padding_texels;
  g.flags = (a.anisotropic ? GLINT_LOD_ANISOTROPIC : 0u) | (a.padding_texels >= 0.0f ? GLINT_LOD_PADDING_CAP : 0u);
  return g;
}

}  // namespace

void LodAtlasConfig::validate() const {
  check_range("LodAtlasConfig::atlas_width", atlas_width, 1, 65536);
  check_range("LodAtlasConfig::atlas_height", atlas_height, 1, 65536);
  check_range("LodAtlasConfig::levels", levels, 1, 17);
  check_range("LodAtlasConfig::bias", bias, -16.0, 16.0);
  check_range("LodAtlasConfig::max_anisotropy", max_anisotropy, 1.0, 64.0);
  if (!(padding_texels < 0.0f)) check_range("LodAtlasConfig::padding_texels", padding_texels, 0.0, 65536.0);
}

float lod_level(const LodQuery& query, const LodAtlasConfig& atlas) {
  atlas.validate();
  return lod_math::glint_lod(to_glsl(query), to_glsl_atlas(atlas));
}

struct LodBatch::Impl {
  const Context* context;
  detail::ComputePipeline pipeline;
};

LodBatch::LodBatch(const Context& context) : impl_(new Impl{&context, {}}) {
  detail::PipelineDesc d;
  d.kernel_id = "lod_batch_main";
  d.bindings = {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER};
  d.push_constant_bytes = sizeof(LodPush);
  d.workgroup = {64, 1};
  try {
    impl_->pipeline = detail::ComputePipeline(context, d);
  } catch (...) {
    delete impl_;
    throw;
  }
}

LodBatch::~LodBatch() { delete impl_; }

void LodBatch::record(VkCommandBuffer cmd, Buffer& queries, Buffer& levels, uint32_t count, const LodAtlasConfig& atlas,
                      Profiler* profiler) {
  detail::check_command_buffer("LodBatch::record", cmd);
  atlas.validate();
  const uint32_t max_count = 65535u * 64u;  // one dispatch row of 64-wide groups
  if (count > max_count) {
    throw Error(ErrorCode::invalid_argument,
                concat("LodBatch::record: count = ", count, " is out of range: accepted 0 to ", max_count));
  }
  detail::check_buffer("LodBatch::record", "queries", queries,
                       std::max<VkDeviceSize>(1, VkDeviceSize(count) * sizeof(LodQuery)),
                       VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  detail::check_buffer("LodBatch::record", "levels", levels,
                       std::max<VkDeviceSize>(1, VkDeviceSize(count) * sizeof(float)),
                       VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  if (count == 0) return;
  detail::Barriers b;
  b.use(queries, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_READ_BIT);
  b.use(levels, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
  b.flush(cmd);
  LodPush push{to_glsl_atlas(atlas), count};
  impl_->pipeline.dispatch(cmd, {queries, levels}, push, count, 1);
  if (profiler) profiler->mark(cmd, "lod batch");
}

}  // namespace glint
