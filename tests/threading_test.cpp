// The threading contract of include/glint/glint.h, under validation (whose thread checker reports
// unsynchronized use of a queue, fence or pool as "THREADING ERROR"): several threads submitting
// through one Context, constructing effects on it, and recording different effects into their own
// command buffers at the same time.
#include <glint/bloom.h>
#include <glint/blur.h>
#include <glint/flare_pass.h>

#include <atomic>
#include <barrier>
#include <thread>
#include <vector>

#include "core/context_state.h"
#include "core/resources.h"
#include "support/gpu_test.h"
#include "support/transfer.h"

namespace glint::test {
namespace {

constexpr int kThreads = 4;

class ThreadingTest : public GpuTest {};

// Runs `body(thread index)` on kThreads threads that start together; rethrows nothing, counts
// exceptions (each is a failure).
template <typename Body>
int run_threads(Body body) {
  std::atomic<int> failures{0};
  std::barrier start(kThreads);
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t) {
    threads.emplace_back([&, t] {
      start.arrive_and_wait();
      try {
        body(t);
      } catch (const std::exception& e) {
        ADD_FAILURE() << "thread " << t << ": " << e.what();
        ++failures;
      }
    });
  }
  for (auto& th : threads) th.join();
  return failures.load();
}

TEST_F(ThreadingTest, RunOnceFromSeveralThreads) {
  std::vector<detail::OwnedBuffer> buffers;
  for (int t = 0; t < kThreads; ++t) {
    buffers.emplace_back(context(), 4096, VK_BUFFER_USAGE_TRANSFER_DST_BIT, true);
  }
  EXPECT_EQ(run_threads([&](int t) {
              for (uint32_t i = 0; i < 25; ++i) {
                context().run_once([&](VkCommandBuffer cmd) {
                  vkCmdFillBuffer(cmd, buffers[t].buffer(), 0, VK_WHOLE_SIZE, uint32_t(t) * 1000 + i);
                  detail::record_host_read_barrier(cmd);
                });
                buffers[t].invalidate();
                const uint32_t got = *static_cast<const uint32_t*>(buffers[t].mapped());
                if (got != uint32_t(t) * 1000 + i) throw std::runtime_error("fill " + std::to_string(i) + " lost");
              }
            }),
            0);
}

// LensFlarePass submits its atlas generation through run_once() in its constructor; Bloom and the
// blurs compile (or find) their kernels in the shared cache.
TEST_F(ThreadingTest, ConstructingEffectsOnSeveralThreads) {
  EXPECT_EQ(run_threads([&](int t) {
              for (int i = 0; i < 3; ++i) {
                FlarePassConfig pc;
                pc.extent = {64u + 8u * uint32_t(t), 48};
                LensFlarePass pass(context(), pc);
                Bloom bloom(context());
                bloom.prepare({96, 64});
                BlurPyramid pyramid(context(), BlurPyramidConfig{});
                GaussianBlurConfig gc;
                gc.sigma_px = 2.0f + float(t);
                GaussianBlur gauss(context(), gc);
              }
            }),
            0);
}

// Each thread records its own Bloom into its own command buffer (from its own pool) at the same
// time; the submissions then go one by one. Every thread's output must equal a bloom recorded
// alone.
TEST_F(ThreadingTest, RecordingDifferentEffectsIntoDifferentCommandBuffersConcurrently) {
  const VkExtent2D size{96, 64};
  const CpuImage input = random_hdr(size.width, size.height, 77);
  struct Slot {
    detail::OwnedImage in, out;
    std::unique_ptr<Bloom> bloom;
    VkCommandPool pool = VK_NULL_HANDLE;
    VkCommandBuffer cmd = VK_NULL_HANDLE;
  };
  std::vector<Slot> slots(kThreads);
  const VkDevice device = context().device();
  for (Slot& s : slots) {
    s.in = detail::OwnedImage(context(), size, VK_FORMAT_R16G16B16A16_SFLOAT, detail::kToolImageUsage);
    s.out = detail::OwnedImage(context(), size, VK_FORMAT_R16G16B16A16_SFLOAT, detail::kToolImageUsage);
    detail::upload(context(), s.in.state, input);
    s.bloom = std::make_unique<Bloom>(context());
    VkCommandPoolCreateInfo pi{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    pi.queueFamilyIndex = context().queue_family_index();
    ASSERT_EQ(vkCreateCommandPool(device, &pi, nullptr, &s.pool), VK_SUCCESS);
    VkCommandBufferAllocateInfo ai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    ai.commandPool = s.pool;
    ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    ai.commandBufferCount = 1;
    ASSERT_EQ(vkAllocateCommandBuffers(device, &ai, &s.cmd), VK_SUCCESS);
  }
  EXPECT_EQ(run_threads([&](int t) {
              Slot& s = slots[t];
              VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
              begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
              if (vkBeginCommandBuffer(s.cmd, &begin) != VK_SUCCESS) throw std::runtime_error("begin");
              s.bloom->record(s.cmd, s.in.state, s.out.state);
              if (vkEndCommandBuffer(s.cmd) != VK_SUCCESS) throw std::runtime_error("end");
            }),
            0);
  // Submit one by one, under the lock run_once() takes, so the queue is never used by two threads.
  for (Slot& s : slots) {
    VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    submit.commandBufferCount = 1;
    submit.pCommandBuffers = &s.cmd;
    std::lock_guard<std::recursive_mutex> lock(context().state().submit_mutex);
    ASSERT_EQ(vkQueueSubmit(context().state().queue, 1, &submit, VK_NULL_HANDLE), VK_SUCCESS);
    ASSERT_EQ(vkQueueWaitIdle(context().state().queue), VK_SUCCESS);
  }
  // The same bloom recorded alone.
  detail::OwnedImage in(context(), size, VK_FORMAT_R16G16B16A16_SFLOAT, detail::kToolImageUsage);
  detail::OwnedImage out(context(), size, VK_FORMAT_R16G16B16A16_SFLOAT, detail::kToolImageUsage);
  detail::upload(context(), in.state, input);
  Bloom alone(context());
  context().run_once([&](VkCommandBuffer cmd) { alone.record(cmd, in.state, out.state); });
  const CpuImage want = detail::download(context(), out.state);
  for (Slot& s : slots) {
    const CpuImage got = detail::download(context(), s.out.state);
    EXPECT_EQ(got.rgba, want.rgba);
    vkDestroyCommandPool(device, s.pool, nullptr);
  }
}

}  // namespace
}  // namespace glint::test
