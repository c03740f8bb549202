// Atlas-aware texture LOD: the mip level a sampler should use for a sub-texture inside an atlas,
// following the Vulkan specification's LOD operation with the exact gradient length. The same
// function is available to any GLSL shader (<glint/gpu/lod.glsl>, installed), on the host
// (lod_level(), or the header-only twin glint::lod_math in <glint/gpu/lod_impl.h>), and as a batch
// kernel (LodBatch). docs/LOD.md derives it.
#pragma once

#include <glint/glint.h>
#include <glint/gpu/lod.h>

#include <cstddef>
#include <cstdint>

namespace glint {

/// One query. Layout equals GlintLodQuery (<glint/gpu/lod.h>, what the GPU reads): 8 floats, 32 bytes.
struct LodQuery {
  float dudx = 0, dvdx = 0;    //!< derivatives of the tile's own UV (0..1 across the tile) along screen x
  float dudy = 0, dvdy = 0;    //!< ... along screen y. For REPEAT inside a tile, of the unwrapped UV.
  float tex_w = 1, tex_h = 1;  //!< tile size in texels at level 0 (>= 1)
  float off_x = 0, off_y = 0;  //!< tile offset in the atlas in texels (tile must lie inside the atlas)
};

static_assert(sizeof(LodQuery) == sizeof(GlintLodQuery) && offsetof(LodQuery, dudx) == offsetof(GlintLodQuery, dudx) &&
                  offsetof(LodQuery, dvdy) == offsetof(GlintLodQuery, dvdy) &&
                  offsetof(LodQuery, tex_w) == offsetof(GlintLodQuery, tex_w) &&
                  offsetof(LodQuery, off_y) == offsetof(GlintLodQuery, off_y),
              "LodQuery is laid out as GlintLodQuery");

/// The atlas and sampling settings for a batch of queries. Checked by validate().
struct LodAtlasConfig {
  uint32_t atlas_width = 4096;   //!< atlas size in texels at level 0 (1 to 65536)
  uint32_t atlas_height = 4096;  //!< (1 to 65536)
  uint32_t levels = 13;          //!< mip levels in the atlas (1 to 17)
  float bias = 0.0f;             //!< LOD bias (-16 to 16); not -0.5: no hidden sharpening
  bool anisotropic = false;      //!< anisotropic LOD (lambda = log2(rho_max / eta))
  float max_anisotropy = 16.0f;  //!< maxAnisotropy when anisotropic (1 to 64)
  float padding_texels = -1.0f;  //!< padding around each tile at level 0; < 0: no padding cap
                                 //!< (0 to 65536 to enable the cap)
  void validate() const;
};

/// The level for one query, computed on the CPU with the same source as the GPU kernels.
/// Invalid queries (NaN, tile outside the atlas, size < 1) give level 0.
float lod_level(const LodQuery& query, const LodAtlasConfig& atlas);

/// Evaluates N queries from a storage buffer into N floats (levels) on the GPU.
class LodBatch {
 public:
  explicit LodBatch(const Context& context);
  LodBatch(const LodBatch&) = delete;
  LodBatch& operator=(const LodBatch&) = delete;
  ~LodBatch();

  /// Records the evaluation of `count` queries (LodQuery array in `queries`) into `levels`
  /// (`count` floats). Both buffers need STORAGE_BUFFER usage and at least count * 32 and
  /// count * 4 bytes. Their state fields are updated. count == 0 records nothing; count is at
  /// most 4,194,240 (65535 groups of 64) per call.
  /// Throws Error before recording if a buffer is null, too small or lacks the usage, or if
  /// `atlas` is invalid.
  void record(VkCommandBuffer cmd, Buffer& queries, Buffer& levels, uint32_t count, const LodAtlasConfig& atlas,
              Profiler* profiler = nullptr);

  struct Impl;

 private:
  Impl* impl_;
};

}  // namespace glint
