// The deterministic RNG: known outputs of xoshiro256** seeded through splitmix64
// (computed with an independent implementation of both published algorithms),
// ranges and moments of uniform() and normal(), and exact state round trips.
#include "core/rng.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <set>
#include <vector>

namespace diverse {
namespace {

TEST(Rng, KnownOutputs) {
  Rng zero(0);
  EXPECT_EQ(zero.next_u64(), 0x99ec5f36cb75f2b4ULL);
  EXPECT_EQ(zero.next_u64(), 0xbf6e1f784956452aULL);
  EXPECT_EQ(zero.next_u64(), 0x1a5f849d4933e6e0ULL);
  Rng r42(42);
  EXPECT_EQ(r42.next_u64(), 0x15780b2e0c2ec716ULL);
  EXPECT_EQ(r42.next_u64(), 0x6104d9866d113a7eULL);
  EXPECT_EQ(r42.next_u64(), 0xae17533239e499a1ULL);
  // uniform() is the top 53 bits scaled by 2^-53.
  Rng one(1);
  EXPECT_EQ(one.uniform(), static_cast<double>(0xb3f2af6d0fc710c5ULL >> 11) * 0x1.0p-53);
}

TEST(Rng, SameSeedSameSequenceOtherSeedOtherSequence) {
  Rng a(123), b(123), c(124);
  int differ = 0;
  for (int i = 0; i < 1000; ++i) {
    const double x = a.normal();
    EXPECT_EQ(x, b.normal());
    differ += x != c.normal();
  }
  EXPECT_GT(differ, 990);
}

TEST(Rng, UniformRangeAndMoments) {
  Rng rng(7);
  const int count = 1000000;
  double sum = 0, sum_sq = 0, lo = 1, hi = 0;
  for (int i = 0; i < count; ++i) {
    const double u = rng.uniform();
    ASSERT_GE(u, 0.0);
    ASSERT_LT(u, 1.0);
    sum += u;
    sum_sq += u * u;
    lo = std::min(lo, u);
    hi = std::max(hi, u);
  }
  const double mean = sum / count, var = sum_sq / count - mean * mean;
  // Standard errors: sqrt(1/12 / N) = 2.9e-4 for the mean, about 7.5e-5 for the variance.
  EXPECT_NEAR(mean, 0.5, 5 * 2.9e-4);
  EXPECT_NEAR(var, 1.0 / 12.0, 5 * 7.5e-5);
  EXPECT_LT(lo, 1e-5);
  EXPECT_GT(hi, 1 - 1e-5);
}

TEST(Rng, NormalMoments) {
  Rng rng(11);
  const int count = 1000000;
  double sum = 0, sum_sq = 0, sum_4 = 0;
  int beyond_two = 0;
  for (int i = 0; i < count; ++i) {
    const double z = rng.normal();
    ASSERT_TRUE(std::isfinite(z));
    sum += z;
    sum_sq += z * z;
    sum_4 += z * z * z * z;
    beyond_two += std::abs(z) > 2;
  }
  const double mean = sum / count, var = sum_sq / count - mean * mean;
  // Standard errors: 1e-3 for the mean, sqrt(2 / N) = 1.4e-3 for the variance.
  EXPECT_NEAR(mean, 0.0, 5e-3);
  EXPECT_NEAR(var, 1.0, 7e-3);
  EXPECT_NEAR(sum_4 / count, 3.0, 0.05);  // kurtosis of a normal
  // P(|z| > 2) = 0.0455; standard error 2.1e-4.
  EXPECT_NEAR(static_cast<double>(beyond_two) / count, 0.0455, 1.1e-3);
}

TEST(Rng, StateRoundTripIncludesCachedDeviate) {
  Rng rng(99);
  rng.normal();  // leaves a cached second deviate
  const Rng::State saved = rng.state();
  EXPECT_TRUE(saved.has_spare);
  std::vector<double> expected;
  for (int i = 0; i < 11; ++i) expected.push_back(rng.normal());
  const std::uint64_t expected_u64 = rng.next_u64();

  Rng restored(12345);
  restored.set_state(saved);
  EXPECT_EQ(restored.state(), saved);
  for (double e : expected) EXPECT_EQ(restored.normal(), e);
  EXPECT_EQ(restored.next_u64(), expected_u64);
}

TEST(Rng, DerivedSeedsAreDistinctAndStable) {
  EXPECT_EQ(derive_seed(1, {2, 3}), derive_seed(1, {2, 3}));
  std::set<std::uint64_t> seeds;
  for (std::uint64_t g = 0; g < 100; ++g) {
    for (std::uint64_t v = 0; v < 10; ++v) seeds.insert(derive_seed(5, {g, v}));
  }
  EXPECT_EQ(seeds.size(), 1000u);
  EXPECT_NE(derive_seed(5, {1, 2}), derive_seed(5, {2, 1}));
  EXPECT_NE(derive_seed(5, {}), derive_seed(6, {}));
  EXPECT_NE(derive_seed(5, {0}), derive_seed(5, {}));
}

}  // namespace
}  // namespace diverse
