// record() performs no heap allocation once an effect has seen its images (the README's promise
// for the frame path). The test replaces the global operator new of this program with one that
// counts calls made while a thread-local flag is set, records a first frame of every effect (which
// may make descriptor sets and per-size resources), then counts the allocations of the second
// frame's record() calls, profiler marks included. Drivers and layers may be written in C++ and
// allocate through the same operator new inside vkCmd* calls (lavapipe and the validation layer
// do); an allocation counts only when the nearest caller outside the C++ runtime is this program,
// where glint is linked statically (found with backtrace() and dladdr()).
#include <dlfcn.h>
#include <execinfo.h>
#include <glint/bloom.h>
#include <glint/blur.h>
#include <glint/flare_pass.h>
#include <glint/lod.h>

#include <cstdlib>
#include <cstring>
#include <new>
#include <string>

#include "core/resources.h"
#include "support/flare_scene.h"
#include "support/gpu_test.h"
#include "support/transfer.h"

// The replacements below pair operator new with malloc and operator delete with free, which is
// correct; GCC's -Wmismatched-new-delete sees a free() of what `new` returned once they inline.
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"

namespace {
thread_local bool g_counting = false;
thread_local uint64_t g_allocations = 0;

// Whether an allocation whose operator new was called from `caller` comes from this program's
// code: the first return address, from `caller` up, outside the C++ runtime (libstdc++ and the
// std:: templates instantiated here, whose containers and streams allocate on behalf of whoever
// called them) lies in the main executable.
bool called_from_this_program(void* caller) {
  Dl_info self{};
  if (!dladdr(reinterpret_cast<void*>(&called_from_this_program), &self)) return true;
  auto where = [&](void* address) {  // 0 this program, 1 the C++ runtime, 2 anything else
    Dl_info info{};
    if (!dladdr(address, &info) || !info.dli_fname) return 2;
    // The C++ runtime, and its templates instantiated in this program (std::string members that
    // a library calls may resolve to this program's copy).
    if (std::strstr(info.dli_fname, "libstdc++") || std::strstr(info.dli_fname, "libgcc")) return 1;
    if (info.dli_sname &&
        (std::strncmp(info.dli_sname, "_ZNSt", 5) == 0 || std::strncmp(info.dli_sname, "_ZNKSt", 6) == 0 ||
         std::strncmp(info.dli_sname, "_ZSt", 4) == 0))
      return 1;
    if (info.dli_fbase == self.dli_fbase) return 0;
    return 2;
  };
  const int first = where(caller);
  if (first != 1) return first == 0;
  void* frames[32];
  const int n = backtrace(frames, 32);
  int i = 0;
  while (i < n && frames[i] != caller) ++i;
  for (; i < n; ++i) {
    const int w = where(frames[i]);
    if (w != 1) return w == 0;
  }
  return true;
}

void count_allocation(void* caller) {
  if (!g_counting) return;
  g_counting = false;  // backtrace() and dladdr() may allocate
  if (called_from_this_program(caller)) ++g_allocations;
  g_counting = true;
}

void* counted_new(std::size_t size, void* caller) {
  count_allocation(caller);
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
void* counted_new_aligned(std::size_t size, std::align_val_t align, void* caller) {
  count_allocation(caller);
  const std::size_t a = static_cast<std::size_t>(align);
  if (void* p = std::aligned_alloc(a, (size + a - 1) / a * a)) return p;
  throw std::bad_alloc();
}
}  // namespace

// Each records its caller (the code that asked for memory) before anything can inline it away.
void* operator new(std::size_t size) { return counted_new(size, __builtin_return_address(0)); }
void* operator new[](std::size_t size) { return counted_new(size, __builtin_return_address(0)); }
void* operator new(std::size_t size, std::align_val_t a) {
  return counted_new_aligned(size, a, __builtin_return_address(0));
}
void* operator new[](std::size_t size, std::align_val_t a) {
  return counted_new_aligned(size, a, __builtin_return_address(0));
}
void* operator new(std::size_t size, const std::nothrow_t&) noexcept {
  try {
    return counted_new(size, __builtin_return_address(0));
  } catch (...) {
    return nullptr;
  }
}
void* operator new[](std::size_t size, const std::nothrow_t&) noexcept {
  try {
    return counted_new(size, __builtin_return_address(0));
  } catch (...) {
    return nullptr;
  }
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }

namespace glint::test {
namespace {

class AllocationTest : public GpuTest {};

// Allocations made by `body` on this thread.
template <typename Body>
uint64_t allocations_in(Body body) {
  g_allocations = 0;
  g_counting = true;
  body();
  g_counting = false;
  return g_allocations;
}

TEST_F(AllocationTest, TheCounterSeesAnAllocation) {
  // So that a zero below means "none", not "not counted".
  EXPECT_EQ(allocations_in([] { delete new std::string(100, 'x'); }), 2u);  // the string and its buffer
  // And one made inside the C++ runtime on this program's behalf.
  EXPECT_EQ(allocations_in([] { std::vector<int>(1000).swap(*std::make_unique<std::vector<int>>()); }), 2u);
}

TEST_F(AllocationTest, ASteadyStateFrameOfEveryEffectAllocatesNothing) {
  constexpr VkFormat kF16 = VK_FORMAT_R16G16B16A16_SFLOAT;
  const VkExtent2D size{96, 64};
  auto in = make_image(random_hdr(size.width, size.height, 5), kF16);
  auto out = make_poisoned(size, kF16);
  Profiler profiler(context(), 256);

  Bloom bloom(context());
  BlurPyramid pyramid(context());
  std::vector<std::unique_ptr<GaussianBlur>> gauss;
  for (BlurMethod m : {BlurMethod::separable, BlurMethod::pyramid, BlurMethod::dual}) {
    GaussianBlurConfig gc;
    gc.sigma_px = 6.0f;
    gc.method = m;
    gauss.push_back(std::make_unique<GaussianBlur>(context(), gc));
  }

  LodBatch lod(context());
  HostBuffer queries(64 * sizeof(LodQuery)), levels(64 * sizeof(float));

  // The raster pass culls 100 lights with a 16 x 16 grid, more than its culler's one_group_lights()
  // (64 at N = 16 on every device): the four dispatches. The compute pass culls 16 lights in one
  // workgroup.
  std::vector<std::unique_ptr<LensFlarePass>> passes;
  std::vector<uint32_t> counts;
  for (FlareDrawPath path : {FlareDrawPath::raster, FlareDrawPath::compute}) {
    FlarePassConfig pc;
    pc.extent = size;
    pc.draw = path;
    pc.cull.capacity = 64;
    pc.cull.grid = path == FlareDrawPath::raster ? 16 : 4;
    pc.per_light_results = true;
    passes.push_back(std::make_unique<LensFlarePass>(context(), pc));
    counts.push_back(path == FlareDrawPath::raster ? 100 : 16);
  }
  reference::DepthImage far{size.width, size.height, std::vector<float>(size_t(size.width) * size.height, 1.0f)};
  auto depth = make_depth(far, VK_FORMAT_D32_SFLOAT);
  detail::OwnedImage color(context(), size, kF16, detail::kToolImageUsage | VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT);
  detail::upload(context(), color.state, random_hdr(size.width, size.height, 6));
  std::vector<GlintFlareLight> list(100);
  for (size_t i = 0; i < list.size(); ++i) {
    list[i] = GlintFlareLight{};
    list[i].position_x = -0.9f + 0.018f * float(i);
    list[i].position_z = 0.5f;
    list[i].intensity = list[i].color_r = list[i].color_g = list[i].color_b = 1.0f;
    list[i].size_px = 8.0f;
    list[i].enabled = 1;
  }
  HostBuffer lights(list.size() * sizeof(GlintFlareLight));
  std::memcpy(lights.owned.mapped(), list.data(), list.size() * sizeof(GlintFlareLight));
  lights.owned.flush();
  const float view_proj[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  const FlareConfig look = FlareConfig::preset(FlarePreset::cinematic);

  // One frame of everything; `count` says whether its allocations are counted.
  struct Counts {
    uint64_t bloom = 0, pyramid = 0, gauss = 0, lod = 0, flare = 0;
  };
  auto frame = [&](VkCommandBuffer cmd, Counts& c) {
    profiler.reset(cmd);
    c.bloom += allocations_in([&] { bloom.record(cmd, in.state, out.state, &profiler); });
    c.pyramid += allocations_in([&] { pyramid.record(cmd, in.state, &profiler); });
    for (auto& g : gauss) c.gauss += allocations_in([&] { g->record(cmd, in.state, out.state, &profiler); });
    c.lod += allocations_in([&] { lod.record(cmd, queries.view, levels.view, 64, LodAtlasConfig{}, &profiler); });
    for (size_t i = 0; i < passes.size(); ++i) {
      c.flare += allocations_in([&] {
        passes[i]->record(cmd, color.state, depth.state, lights.view, counts[i], view_proj, look, &profiler);
      });
    }
  };
  Counts first, second;
  context().run_once([&](VkCommandBuffer cmd) { frame(cmd, first); });
  EXPECT_GT(first.bloom + first.pyramid + first.gauss + first.lod + first.flare, 0u)
      << "the first frame makes descriptor sets, so it allocates: the counter works inside record()";
  context().run_once([&](VkCommandBuffer cmd) { frame(cmd, second); });
  EXPECT_EQ(second.bloom, 0u) << "Bloom::record";
  EXPECT_EQ(second.pyramid, 0u) << "BlurPyramid::record";
  EXPECT_EQ(second.gauss, 0u) << "GaussianBlur::record (separable, pyramid, dual)";
  EXPECT_EQ(second.lod, 0u) << "LodBatch::record";
  EXPECT_EQ(second.flare, 0u)
      << "LensFlarePass::record (Hi-Z, cull in one workgroup and in four dispatches, raster and compute draws)";
}

}  // namespace
}  // namespace glint::test
