// Occlusion culling of caller objects on the GPU (docs/OCCLUSION.md, "Object culling"), the way
// GPU-driven renderers cull draws (Haar & Aaltonen, SIGGRAPH 2015; Wihlidal, GDC 2016;
// zeux/niagara): every object is a world-space bounding sphere or box (GlintCullObject,
// include/glint/gpu/object_cull.h); the culler tests it against the frustum and against the Hi-Z
// pyramid (HiZPyramid, glint/occlusion.h) at the level where its screen rectangle covers at most
// 2x2 texels, writes its state to a persistent visibility buffer, and compacts the payloads of the
// emitted objects, in object order, into a list with a draw count and dispatch arguments. Every
// result stays on the GPU.
//
// Conventions (Vulkan): clip = proj * view * (p, 1); ndc = clip.xyz / clip.w; pixel =
// (ndc.xy * 0.5 + 0.5) * depth size (ndc.y = -1 is the first row); depth = ndc.z in [0, 1], 0 near
// for standard Z, 1 near for reversed Z; far plane finite or at infinity.
//
// The test is conservative: an object is never culled if any point of its bound lies inside the
// frustum and in front of the stored depth (docs/OCCLUSION.md proves it, fp32 rounding included).
// Bounds crossing the near plane are visible; malformed bounds (non-finite values, negative radius,
// min > max, unknown kind) are visible and counted as invalid.
//
// Two-phase frame (niagara):
//   culler.record_phase1(cmd, frame, objects, early);   // history-visible objects in the frustum
//   ... draw early.list (count early.indirect); render depth; hiz.record(cmd, depth);
//   culler.record_phase2(cmd, hiz, depth, frame, objects, late);  // the newly visible ones
//   ... draw late.list
// Single phase: culler.record(cmd, hiz, depth, frame, objects, out) tests all and emits every
// visible object. Before the first frame, zero the visibility buffer (all objects not visible;
// ObjectCuller::record_clear_history does it).
#pragma once

#include <glint/glint.h>
#include <glint/gpu/object_cull.h>
#include <glint/occlusion.h>

#include <cstdint>
#include <memory>

namespace glint {

namespace detail {
struct ObjectCullerAccess;  // benchmark and test switches (src/visibility/object_cull_internal.h)
}  // namespace detail

/// Creation-time settings of an ObjectCuller. Checked by validate().
struct ObjectCullConfig {
  uint32_t max_objects = 1u << 20;  //!< most objects per record (1 to 268435456 = 2^28); the culler
                                    //!< keeps 16 bytes per 64 objects
  uint32_t capacity = 1u << 20;     //!< slots of the output list (1 to 268435456)
  /// Words (4 bytes) of payload per object, copied into the list (1 to 64, e.g. 5 for a
  /// VkDrawIndexedIndirectCommand), or 0: the list holds each emitted object's index (one uint).
  uint32_t payload_words = 0;
  uint32_t objects_per_group = 64;  //!< dispatch arguments: group_count_x = ceil(written / this) (1 to 1024)
  bool reversed_z = false;          //!< depth 1 near; must match the HiZConfig and the projection

  /// Throws Error(invalid_argument) naming the field and the accepted range.
  void validate() const;
};

/// One frame's camera and object count.
struct ObjectCullFrame {
  /// Column-major view matrix (GLM): affine (row 3 = 0, 0, 0, 1), finite.
  float view[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  /// Column-major Vulkan perspective projection (GLM perspective/perspectiveRH_ZO/infinite, with
  /// or without y flip, off-centre allowed): P00 != 0, P11 != 0, P02, P12, P22, P23 any finite,
  /// P32 = -1 or +1 (w = +-z_view), every other entry 0. The depth direction must match
  /// ObjectCullConfig::reversed_z (standard: depth grows with distance; reversed: shrinks) and the
  /// near plane must lie in front of the camera.
  float proj[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, -1, -1, 0, 0, -1, 0};  // infinite far, near 1
  uint32_t count = 0;  //!< objects (0 to ObjectCullConfig::max_objects)
};

/// The caller's per-object buffers. glint updates their state fields.
struct ObjectCullBuffers {
  Buffer objects;     //!< GlintCullObject[count] (32 bytes each); STORAGE usage; read
  Buffer payloads;    //!< uint[count * payload_words]; STORAGE usage; read; ignored (may be null)
                      //!< when payload_words is 0
  Buffer visibility;  //!< uint[count] GLINT_OBJECT_STATE_*; STORAGE usage; persistent: read by
                      //!< phase 1 and 2 as the history, written by record() and phase 2
};

/// The buffers one cull writes. The caller owns them; their state fields are updated.
struct ObjectCullOutputs {
  Buffer list;      //!< capacity * max(1, payload_words) uints; STORAGE usage (add INDIRECT to draw
                    //!< from it). The emitted objects' payloads (or indices) in increasing object
                    //!< index; when more are emitted than capacity, the lowest indices.
  Buffer indirect;  //!< one GlintObjectCullIndirect (16 bytes): draw count at offset 0 (for
                    //!< vkCmdDrawIndexedIndirectCount), VkDispatchIndirectCommand at offset 4;
                    //!< STORAGE | INDIRECT usage
  Buffer stats;     //!< one GlintObjectCullStats (32 bytes); STORAGE usage; glint never waits on it
};

/// Frustum + Hi-Z occlusion cull and ordered compaction of caller objects.
class ObjectCuller {
 public:
  /// Throws Error(invalid_argument) if config is invalid, Error(unsupported_size) if max_objects x 32
  /// bytes, max_objects x payload_words x 4 or capacity x max(1, payload_words) x 4 exceeds the
  /// device's maxStorageBufferRange (at least 2^27 bytes: 4 M objects), or if the workgroups for
  /// max_objects exceed maxComputeWorkGroupCount.
  ObjectCuller(const Context& context, const ObjectCullConfig& config = {});
  ObjectCuller(const ObjectCuller&) = delete;
  ObjectCuller& operator=(const ObjectCuller&) = delete;
  ObjectCuller(ObjectCuller&&) noexcept;
  ObjectCuller& operator=(ObjectCuller&&) noexcept;
  ~ObjectCuller();

  /// Single phase: tests all `frame.count` objects against the frustum and `hiz` (built from
  /// `depth`), writes every state to buffers.visibility and emits the visible objects. Three
  /// dispatches (test, tile scan, scatter, which also writes `indirect` and `stats`); the outputs
  /// are the same bits on every run, and nothing is carried from one record to the next.
  /// Afterwards the outputs and the visibility were last written by the compute shader stage: a
  /// draw needs a barrier to DRAW_INDIRECT / INDIRECT_COMMAND_READ for `indirect` (and `list` when
  /// it holds draw commands). Throws Error before recording anything if: frame.count exceeds
  /// max_objects; a view or proj entry is non-finite or the matrices do not have the form above;
  /// the projection's depth direction disagrees with reversed_z; reversed_z differs from
  /// hiz.config().reversed_z; `depth` does not match `hiz` or lacks SAMPLED usage; a buffer is
  /// null, has size 0 or VK_WHOLE_SIZE, is smaller than stated above or larger than the device's
  /// maxStorageBufferRange, has an offset that is not a
  /// multiple of 4 or lacks a usage.
  void record(VkCommandBuffer cmd, HiZPyramid& hiz, Image& depth, const ObjectCullFrame& frame,
              ObjectCullBuffers& buffers, ObjectCullOutputs& outputs, Profiler* profiler = nullptr);

  /// Phase 1: emits the objects whose history state is VISIBLE and that pass the frustum test of
  /// this frame's camera (no occlusion test, no image read, the history is not written). The
  /// errors of record(), less those about `hiz` and `depth`.
  void record_phase1(VkCommandBuffer cmd, const ObjectCullFrame& frame, ObjectCullBuffers& buffers,
                     ObjectCullOutputs& outputs, Profiler* profiler = nullptr);

  /// Phase 2: tests all objects against `hiz` (built from this frame's phase-1 draws), writes every
  /// state, and emits the visible objects whose history was not VISIBLE, i.e. those phase 1 did
  /// not emit. Phase 1 and 2 together emit every visible object exactly once. Use outputs other
  /// than phase 1's if phase 1's draws may still read them. The errors of record().
  void record_phase2(VkCommandBuffer cmd, HiZPyramid& hiz, Image& depth, const ObjectCullFrame& frame,
                     ObjectCullBuffers& buffers, ObjectCullOutputs& outputs, Profiler* profiler = nullptr);

  /// Zero-fills the first `count` states of `visibility` (no object visible: the first frame's
  /// history). Throws Error(invalid_argument) before recording if count exceeds max_objects or
  /// the buffer is null, smaller than 4 * count bytes or lacks TRANSFER_DST usage.
  void record_clear_history(VkCommandBuffer cmd, Buffer& visibility, uint32_t count);

  const ObjectCullConfig& config() const;
  /// Bytes one record() moves at least: objects, visibility (read and written), group masks, and
  /// the written payloads; the Hi-Z texels read depend on the scene and are not counted.
  uint64_t min_bytes_moved(uint32_t count, uint32_t written) const;

  struct Impl;

 private:
  friend struct detail::ObjectCullerAccess;
  std::unique_ptr<Impl> impl_;
};

}  // namespace glint
