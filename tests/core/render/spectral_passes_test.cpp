// Spectral renders of crystals and gems on the GPU twin (view.comp's passes): the shipped calcite
// rhomb (uniaxial, 224³, both modes at 16 wavelengths) and the diamond brilliant (dispersive,
// many total reflections) rendered by both twins at the same wavelengths per pixel sample.
//
// What failed: view.comp marched every wavelength (and both modes) of a pixel sample in one
// invocation, and lavapipe gives one SIMD group of invocations 65535 loop passes in all, then ends
// every loop silently (docs/view-renderer.md). In the 224³ rhomb each march walks hundreds of
// boundary cells, so 32 marches spent the budget: the GPU image showed the crystal's sides in
// saturated blue and cyan with voxel-sized steps along its edges, while the CPU twin showed grey
// glass. A pass now marches one wavelength (both modes), and a march that runs out anyway is
// counted in RenderImage::cut_samples, never shown as light it did not find.
//
// The bounds: both twins use the same wavelengths per pixel sample (view.comp's hash and the
// reference's), so the images differ by float32 marching only, except in pixels whose ray grazes
// a facet edge or a grid line edge, where float rounding can pick the other side: compare the mean
// |ΔRGB| relative to the mean |RGB| (≤ 1%) and the 95th percentile of |ΔRGB| (≤ 0.02, on
// radiances of order 0.3–1), as Spectral.GpuMatchesCpuInSpectralMode does.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "tests/core/test_support.h"

namespace eikon::test {
namespace {

struct ImageDiff {
  double rel = 0.0, p95 = 0.0, max = 0.0;
};

ImageDiff compare(const RenderImage& g, const RenderImage& c) {
  std::vector<double> diffs;
  double sumDiff = 0.0, sumVal = 0.0;
  for (size_t i = 0; i < g.rgb.size(); ++i) {
    const double d = std::abs(double(g.rgb[i]) - double(c.rgb[i]));
    diffs.push_back(d);
    sumDiff += d;
    sumVal += std::abs(double(c.rgb[i]));
  }
  std::sort(diffs.begin(), diffs.end());
  return {sumDiff / sumVal, diffs[size_t(0.95 * double(diffs.size()))], diffs.back()};
}

/// Shipped scene `name` at the given resolution and image size, without its lights, rendered
/// with `rs` by both twins.
struct ShippedTwins {
  RenderImage g, c;
};
ShippedTwins renderShipped(const char* name, int resolution, int width, int height,
                           const RenderSettings& rs) {
  Scene scene =
      loadScene(std::filesystem::path(EIKON_SOURCE_DIR) / "scenes" / (std::string(name) + ".json"));
  scene.volume.resolution = resolution;
  scene.camera.width = width;
  scene.camera.height = height;
  scene.lights.clear();
  const VolumeSet volume = voxelize(scene);
  ViewRenderer gpu(context(), scene, volume);
  const VolumeField field(volume);
  const ReferenceMarcher cpu(field, scene.environment);
  return {gpu.render(rs), cpu.render(scene.camera, rs)};
}

void expectTwinsAgree(const char* name, int resolution, int width, int height,
                      SpectralSampling sampling) {
  RenderSettings rs;
  rs.wavelengths = 16;
  rs.sampling = sampling;
  int passesSeen = 0;
  rs.on_pass = [&](const RenderImage&, int, int) { ++passesSeen; };
  const ShippedTwins t = renderShipped(name, resolution, width, height, rs);
  const RenderImage &g = t.g, &c = t.c;
  const ImageDiff d = compare(g, c);
  std::printf(
      "[ measured ] %s %d^3 %dx%d, 16 wavelengths: %lld cut pixel samples; mean |d|/mean |RGB| "
      "%.3g, 95th percentile |d| %.3g, max %.3g\n",
      name, resolution, width, height, g.cut_samples, d.rel, d.p95, d.max);
  EXPECT_EQ(g.cut_samples, 0);
  EXPECT_LT(d.rel, 0.01);
  EXPECT_LT(d.p95, 0.02);
  EXPECT_EQ(passesSeen, 0);  // one sample per pixel: the last pass is the returned image
  expectNoValidationMessages();
}

TEST(SpectralPasses, CalciteRhombTwinsAgree) {
  expectTwinsAgree("calcite_rhomb", 224, 48, 36, SpectralSampling::Stratified);
}

TEST(SpectralPasses, DiamondBrilliantTwinsAgree) {
  expectTwinsAgree("diamond_brilliant", 64, 40, 30, SpectralSampling::Stratified);
}

// Hero wavelength sampling (docs/spectra.md): one march per pixel sample carries all 16
// wavelengths. The rhomb attenuates (its weights depend on λ, so the hero carries everything from
// the first step) and has two modes; the brilliant disperses at its first facet. The twins share
// the hero, its rotations and the point where the others stop (the first dispersive event).
TEST(SpectralPasses, CalciteRhombHeroTwinsAgree) {
  expectTwinsAgree("calcite_rhomb", 224, 48, 36, SpectralSampling::Hero);
}

TEST(SpectralPasses, DiamondBrilliantHeroTwinsAgree) {
  expectTwinsAgree("diamond_brilliant", 64, 40, 30, SpectralSampling::Hero);
}

// Sharing across passes (view.comp, P.pass.w & 64): the rhomb's stratified passes march one
// wavelength each, but a pixel whose path meets no crystal (the printed grid seen beside the rhomb,
// the sky) is the same path at every wavelength: the sample's first pass marches it at λ_0 (both
// modes) and adds the other 15 wavelengths from its lookups. So, with the AOV layer's steps (all
// of a pixel's marches): where the CPU twin's first interface is not the crystal, the GPU twin
// marched exactly 1/16 of the twin's steps (the twin marches the same path at all 16 wavelengths);
// where it is the crystal, all of them: at least half the twin's steps on ≥ 95% of those pixels
// (not 1/16; the counts themselves differ where the twins' paths do: float and double may cut a
// grazing ray differently, and mode conversion draws with the GPU's D-projection fractions
// against the CPU's exact ones, docs/view-renderer.md "Light transport"); and the pictures agree
// as the twins' do (expectTwinsAgree's bounds).
TEST(SpectralPasses, PathsThatMeetNoCrystalAreMarchedOnce) {
  RenderSettings rs;
  rs.wavelengths = 16;
  rs.sampling = SpectralSampling::Stratified;
  rs.aov_layer = true;
  const ShippedTwins t = renderShipped("calcite_rhomb", 224, 48, 36, rs);
  const RenderImage &g = t.g, &c = t.c;
  const size_t pixels = size_t(g.width) * size_t(g.height);
  ASSERT_EQ(g.aov.size(), pixels * kAovChannels);
  ASSERT_EQ(c.aov.size(), pixels * kAovChannels);
  int shared = 0, sharedExact = 0, crystal = 0, crystalExact = 0, crystalMarched = 0;
  for (size_t i = 0; i < pixels; ++i) {
    const float gs = g.aov[i * kAovChannels + 8], cs = c.aov[i * kAovChannels + 8];
    if (c.aov[i * kAovChannels + 7] == 0.0f) {  // the rhomb is object 0
      ++crystal;
      crystalExact += gs == cs;
      crystalMarched += gs >= 0.5f * cs;
    } else {
      ++shared;
      sharedExact += gs * 16.0f == cs;
    }
  }
  const ImageDiff d = compare(g, c);
  std::printf(
      "[ measured ] calcite rhomb 48x36, 16 wavelengths: %d pixels beside the crystal, %d of them "
      "marched 1/16 of the twin's steps; %d on the crystal, %d marched all (%d the twin's count); "
      "mean steps per ray gpu %.3f, cpu %.3f; mean |d|/mean |RGB| %.3g, 95th percentile |d| %.3g\n",
      shared, sharedExact, crystal, crystalMarched, crystalExact, g.mean_steps, c.mean_steps, d.rel,
      d.p95);
  EXPECT_GT(shared, int(pixels) / 4);
  EXPECT_GT(crystal, int(pixels) / 10);
  EXPECT_EQ(sharedExact, shared);
  EXPECT_GE(crystalMarched, 0.95 * crystal);
  EXPECT_EQ(g.cut_samples, 0);
  EXPECT_LT(d.rel, 0.01);
  EXPECT_LT(d.p95, 0.02);
  expectNoValidationMessages();
}

// Progressive output: with 3 samples per pixel the image so far is handed out after the first and
// the second sample, and is the mean of the finished samples: the running mean of a constant
// environment seen through nothing is that constant.
TEST(SpectralPasses, ImageSoFarAfterEachSample) {
  Twins t(R"({
    "camera": {"position": [0, 0, -20], "look_at": [0, 0, 0], "fov_deg": 20, "width": 16, "height": 12},
    "environment": {"type": "constant", "radiance": [0.2, 0.4, 0.8]},
    "volume": {"bounds_min": [-4, -4, -4], "bounds_max": [4, 4, 4], "resolution": 16},
    "objects": [{"shape": "sphere", "center": [0, 0, 0], "radius": 1, "material": "N-BK7"}]
  })");
  RenderSettings rs;
  rs.spp = 3;
  std::vector<int> done;
  rs.on_pass = [&](const RenderImage& so_far, int n, int spp) {
    done.push_back(n);
    EXPECT_EQ(spp, 3);
    EXPECT_NEAR(so_far.rgb[0], 0.2, 1e-6);  // the corner pixel misses the sphere
    EXPECT_NEAR(so_far.rgb[2], 0.8, 1e-6);
  };
  const RenderImage g = t.gpu->render(rs);
  EXPECT_EQ(done, (std::vector<int>{1, 2}));
  EXPECT_NEAR(g.rgb[1], 0.4, 1e-6);
  expectNoValidationMessages();
}

}  // namespace
}  // namespace eikon::test
