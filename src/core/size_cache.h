// The per-size resources of an effect (pyramid images, planned steps; no descriptor set: those are
// pushed per dispatch), kept for every size the effect is recorded at until no submitted work can use them.
//
// Lifetime rule (Context::begin_frame() documents the caller's side): every slot notes the last
// frame it was recorded into a caller's command buffer (gpu_frame) and the serial of the last
// run_once() command buffer it was recorded into (once). A slot is safe to destroy when
//   (gpu_frame is unset or gpu_frame + frames_in_flight <= frame()) and run_once `once` is over.
// A slot is stale, and destroyed by the next retire_stale(), when it is safe and either was not
// touched (recorded or prepared) for frames_in_flight frames, or was only ever recorded inside
// run_once() calls that are over (tools and tests then keep only the size they use).
// When all kMaxCachedSizes slots are taken, the least recently touched safe slot makes room; if
// none is safe, get() throws before the caller records anything.
//
// Lookups scan a vector reserved to kMaxCachedSizes: no allocation once a size is cached.
#pragma once

#include <glint/glint.h>

#include <cstdint>
#include <limits>
#include <memory>
#include <utility>
#include <vector>

#include "core/check.h"
#include "core/context_state.h"

namespace glint::detail {

/// What a cached entry is made for: the input extent, the output format where steps are
/// specialized for it (else VK_FORMAT_UNDEFINED) and the config generation (bumped by a shape
/// change, so that entries of the old shape are never found again and age out like any other).
struct SizeKey {
  VkExtent2D extent{0, 0};
  VkFormat format = VK_FORMAT_UNDEFINED;
  uint32_t generation = 0;
  bool operator==(const SizeKey& o) const {
    return extent.width == o.extent.width && extent.height == o.extent.height && format == o.format &&
           generation == o.generation;
  }
};

template <typename Entry>
class SizeCache {
 public:
  SizeCache() { slots_.reserve(kMaxCachedSizes); }
  SizeCache(SizeCache&&) noexcept = default;
  SizeCache& operator=(SizeCache&&) noexcept = default;

  void bind(const Context& context) { context_ = &context; }

  /// The entry for `key`, or null. Touches nothing.
  Entry* find(const SizeKey& key) {
    for (Slot& s : slots_) {
      if (s.key == key) return s.entry.get();
    }
    return nullptr;
  }

  /// The entry for `key`, made by `make()` (returning std::unique_ptr<Entry>) if it is not cached.
  /// Retires stale entries other than the result (and other than `keep`, the caller's current
  /// entry, until the new one is made: if make() throws, `keep` is still there). When the cache is
  /// full, destroys the least recently touched safe entry other than `keep`, or throws
  /// Error(invalid_argument) naming `who` if there is none. Marks the entry touched now.
  template <typename Make>
  Entry& get(const SizeKey& key, const Entry* keep, const char* who, Make&& make) {
    if (Entry* e = find(key)) {
      retire_stale(e);
      slot_of(e).touched = frame();
      return *e;
    }
    retire_stale(keep);
    if (slots_.size() >= kMaxCachedSizes) evict_one(keep, who);
    std::unique_ptr<Entry> made = make();
    Slot s;
    s.key = key;
    s.entry = std::move(made);
    s.touched = frame();
    slots_.push_back(std::move(s));  // within the reserved capacity
    Entry* e = slots_.back().entry.get();
    retire_stale(e);  // `keep` too, now that the caller moves on to `e`
    return *e;
  }

  /// Notes that `e` was recorded into `cmd`: a run_once() command buffer, or one of the caller's
  /// in the current frame.
  void recorded(const Entry* e, VkCommandBuffer cmd) {
    Slot& s = slot_of(e);
    const uint64_t f = frame();
    s.touched = f;
    if (const uint64_t serial = context_->state().once_serial(cmd)) {
      s.once = serial;
    } else {
      s.gpu_frame = f;
    }
  }

  /// Destroys the stale entries other than `keep`.
  void retire_stale(const Entry* keep) {
    const uint64_t f = frame();
    const uint32_t n = frames_in_flight();
    for (size_t i = slots_.size(); i-- > 0;) {
      const Slot& s = slots_[i];
      if (s.entry.get() == keep) continue;
      const bool aged = s.touched + n <= f;
      const bool once_only = s.gpu_frame == kNever && s.once != 0;
      if ((aged || once_only) && safe(s)) slots_.erase(slots_.begin() + static_cast<std::ptrdiff_t>(i));
    }
  }

  /// Destroys every entry other than `keep` that no submitted work can use, stale or not.
  void release_unused(const Entry* keep) {
    for (size_t i = slots_.size(); i-- > 0;) {
      if (slots_[i].entry.get() != keep && safe(slots_[i]))
        slots_.erase(slots_.begin() + static_cast<std::ptrdiff_t>(i));
    }
  }

  uint32_t size() const { return static_cast<uint32_t>(slots_.size()); }

  template <typename F>
  void for_each(F&& f) {
    for (Slot& s : slots_) f(*s.entry);
  }

 private:
  static constexpr uint64_t kNever = std::numeric_limits<uint64_t>::max();

  struct Slot {
    SizeKey key;
    std::unique_ptr<Entry> entry;
    uint64_t touched = 0;         // frame of the last record() or prepare()
    uint64_t gpu_frame = kNever;  // frame of the last record() into a caller's command buffer
    uint64_t once = 0;            // serial of the last run_once() command buffer recorded into
  };

  uint64_t frame() const { return context_->state().frame.load(); }
  uint32_t frames_in_flight() const { return context_->state().frames_in_flight; }

  bool safe(const Slot& s) const {
    const bool frames_done = s.gpu_frame == kNever || s.gpu_frame + frames_in_flight() <= frame();
    return frames_done && !context_->state().once_pending(s.once);
  }

  Slot& slot_of(const Entry* e) {
    for (Slot& s : slots_) {
      if (s.entry.get() == e) return s;
    }
    throw Error(ErrorCode::invalid_argument, "internal: size-cache entry not found");
  }

  void evict_one(const Entry* keep, const char* who) {
    size_t victim = slots_.size();
    for (size_t i = 0; i < slots_.size(); ++i) {
      if (slots_[i].entry.get() == keep || !safe(slots_[i])) continue;
      if (victim == slots_.size() || slots_[i].touched < slots_[victim].touched) victim = i;
    }
    if (victim == slots_.size()) {
      throw Error(ErrorCode::invalid_argument,
                  concat(who, ": ", kMaxCachedSizes,
                         " sizes are cached (kMaxCachedSizes) and each may still be used by submitted work (frame ",
                         frame(), ", frames_in_flight ", frames_in_flight(),
                         "); call Context::begin_frame() once per frame, or Context::mark_idle() after waiting "
                         "for the device, so that sizes unused for frames_in_flight frames can be destroyed"));
    }
    slots_.erase(slots_.begin() + static_cast<std::ptrdiff_t>(victim));
  }

  const Context* context_ = nullptr;
  std::vector<Slot> slots_;
};

}  // namespace glint::detail
