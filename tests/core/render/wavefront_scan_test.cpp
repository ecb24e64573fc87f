// The GPU exclusive scan (shaders/scan.comp via GpuScan) that rebuilds the light simulator's patch
// list, against a CPU prefix sum: sizes below, at and above one block (512), not multiples of the
// workgroup, more than one level of block sums, and 1M elements of random 0/1/4 counts (the
// wavefront's outputs). The scan is exact integer arithmetic, so every element must match.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <random>
#include <vector>

#include "core/render/light_simulator.h"
#include "tests/core/test_support.h"

namespace eikon::test {
namespace {

TEST(WavefrontScan, MatchesCpuPrefixSum) {
  GpuScan scan(context());
  std::mt19937 rng(6);
  const uint32_t choices[3] = {0, 1, 4};
  for (size_t n : {size_t(1), size_t(7), size_t(255), size_t(511), size_t(512), size_t(513),
                   size_t(1000), size_t(262143), size_t(262145), size_t(300001), size_t(1) << 20}) {
    std::vector<uint32_t> v(n);
    for (uint32_t& x : v) x = choices[rng() % 3];
    std::vector<uint32_t> want(n);
    uint32_t sum = 0;
    for (size_t i = 0; i < n; ++i) want[i] = sum, sum += v[i];
    std::vector<uint32_t> got = v;
    const auto t0 = std::chrono::steady_clock::now();
    const uint32_t total = scan.exclusiveScan(got);
    const double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    size_t bad = 0;
    for (size_t i = 0; i < n; ++i) bad += got[i] != want[i];
    EXPECT_EQ(total, sum) << "n = " << n;
    EXPECT_EQ(bad, 0u) << "n = " << n;
    if (n == (size_t(1) << 20))
      std::printf("[ measured ] scan of 1M counts: %.1f ms incl. upload/readback\n", ms);
  }
  // Larger values (carries across levels): random up to 2^11, 1M elements, total < 2^32.
  std::vector<uint32_t> v(1000003);
  for (uint32_t& x : v) x = rng() % 2048;
  std::vector<uint32_t> got = v;
  const uint32_t total = scan.exclusiveScan(got);
  uint32_t sum = 0;
  size_t bad = 0;
  for (size_t i = 0; i < v.size(); ++i) bad += got[i] != sum, sum += v[i];
  EXPECT_EQ(total, sum);
  EXPECT_EQ(bad, 0u);
  expectNoValidationMessages();
}

}  // namespace
}  // namespace eikon::test
