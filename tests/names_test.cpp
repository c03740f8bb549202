// The names of the public enums (bloom_filter_name, firefly_guard_name, blur_method_name) for every
// value and for a value outside the enum, and the deprecated to_string(BlurMethod), which must keep
// returning what blur_method_name() returns. CPU only: no Vulkan.
#include <glint/bloom.h>
#include <glint/blur.h>
#include <gtest/gtest.h>

#include <string>

namespace glint {
namespace {

TEST(Names, EveryBlurMethodHasItsName) {
  EXPECT_EQ(std::string(blur_method_name(BlurMethod::automatic)), "auto");
  EXPECT_EQ(std::string(blur_method_name(BlurMethod::separable)), "separable");
  EXPECT_EQ(std::string(blur_method_name(BlurMethod::pyramid)), "pyramid");
  EXPECT_EQ(std::string(blur_method_name(BlurMethod::dual)), "dual");
  EXPECT_EQ(std::string(blur_method_name(static_cast<BlurMethod>(77))), "unknown");
}

TEST(Names, DeprecatedToStringStillNamesEveryBlurMethod) {
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wdeprecated-declarations"
  for (BlurMethod m : {BlurMethod::automatic, BlurMethod::separable, BlurMethod::pyramid, BlurMethod::dual,
                       static_cast<BlurMethod>(77)}) {
    EXPECT_EQ(std::string(to_string(m)), std::string(blur_method_name(m)));
  }
#pragma GCC diagnostic pop
}

TEST(Names, EveryBloomFilterAndGuardHasItsName) {
  EXPECT_EQ(std::string(bloom_filter_name(BloomFilter::cod13)), "cod13");
  EXPECT_EQ(std::string(bloom_filter_name(BloomFilter::dual)), "dual");
  EXPECT_EQ(std::string(bloom_filter_name(BloomFilter::gauss9)), "gauss9");
  EXPECT_EQ(std::string(firefly_guard_name(FireflyGuard::off)), "off");
  EXPECT_EQ(std::string(firefly_guard_name(FireflyGuard::karis)), "karis");
  EXPECT_EQ(std::string(firefly_guard_name(FireflyGuard::karis_smooth)), "karis_smooth");
}

}  // namespace
}  // namespace glint
