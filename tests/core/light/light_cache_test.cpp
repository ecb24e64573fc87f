// The on-disk light cache (core/light/light_cache.h), shared by `eikon render` and Python: an
// entry gives back exactly the volumes stored under its key, the key follows what the light
// simulation reads (the lights, the settings, which twin ran) and ignores what it does not (the
// camera), and a corrupted entry is refused with a notice instead of being rendered. The CLI's
// use of it is tested in tests/apps/input_cli_test.cpp (CorruptedLightCacheIsSimulatedAgain).
#include "core/light/light_cache.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>

#include "core/light/lighting.h"
#include "core/volume/volume_set.h"
#include "tests/core/scene_support.h"

namespace eikon::test {
namespace {

Scene litScene() {
  return parseScene(R"({
    "volume": {"bounds_min": [-2, -2, -2], "bounds_max": [2, 2, 2], "resolution": 6},
    "materials": {"g": {"n": 1.5}},
    "objects": [{"shape": "sphere", "radius": 1, "material": "g"}],
    "lights": [{"type": "directional", "direction": [0, -1, 0], "irradiance": 2}]})",
                    "cache-test.json");
}

/// Light volumes with a distinct, exactly representable value in every component.
void fillLight(VolumeSet& v) {
  clearLighting(v);
  for (size_t i = 0; i < v.light_fluence.size(); ++i) {
    const float f = float(i);
    v.light_fluence[i] = glm::vec4(f + 0.25f, f + 0.5f, f + 0.75f, -f);
    v.light_flux[i] = glm::vec4(2.0f * f, -3.0f * f, 0.125f, 0.0f);
  }
}

TEST(LightCache, AnEntryGivesBackExactlyWhatWasStored) {
  TempDir dir;
  const Scene scene = litScene();
  VolumeSet stored = voxelize(scene);
  fillLight(stored);
  const uint64_t key = lightCacheKey(scene, stored, LightingOptions{}, false);
  ASSERT_EQ(saveLightCache(dir.path(), key, stored), "");

  VolumeSet loaded = voxelize(scene);
  std::string notice;
  EXPECT_FALSE(loadLightCache(dir.path(), key + 1, loaded, &notice));  // no entry: quietly absent
  EXPECT_EQ(notice, "");
  EXPECT_TRUE(loaded.light_fluence.empty());
  ASSERT_TRUE(loadLightCache(dir.path(), key, loaded, &notice));
  EXPECT_EQ(notice, "");
  ASSERT_EQ(loaded.light_fluence.size(), stored.light_fluence.size());
  ASSERT_EQ(loaded.light_flux.size(), stored.light_flux.size());
  for (size_t i = 0; i < stored.light_fluence.size(); ++i) {
    ASSERT_EQ(loaded.light_fluence[i], stored.light_fluence[i]) << "voxel " << i;
    ASSERT_EQ(loaded.light_flux[i], stored.light_flux[i]) << "voxel " << i;
  }
}

TEST(LightCache, KeyFollowsWhatTheSimulationReads) {
  const Scene scene = litScene();
  const VolumeSet v = voxelize(scene);
  const LightingOptions o;
  const uint64_t key = lightCacheKey(scene, v, o, false);
  EXPECT_EQ(lightCacheKey(scene, v, o, false), key);
  EXPECT_NE(lightCacheKey(scene, v, o, true), key);  // the other twin ran

  Scene brighter = scene;
  brighter.lights[0].irradiance = 3.0;
  EXPECT_NE(lightCacheKey(brighter, v, o, false), key);
  LightingOptions finer = o;
  finer.wave.split_span_voxels = 0.5;
  EXPECT_NE(lightCacheKey(scene, v, finer, false), key);
  LightingOptions moreBands = o;
  moreBands.bands = 7;
  EXPECT_NE(lightCacheKey(scene, v, moreBands, false), key);

  Scene elsewhere = scene;  // the light volumes do not depend on the camera
  elsewhere.camera.position = glm::dvec3(5, 6, 7);
  elsewhere.camera.width = 17;
  EXPECT_EQ(lightCacheKey(elsewhere, v, o, false), key);
}

// Sharp interfaces: a scene voxelised with "interfaces": "sharp" is lit through its
// exact boundaries, with "smoothed" through the smoothed field (the index volumes the key hashes
// may be the same), so a cached smoothed light must not serve the sharp scene, nor a light
// simulated with LightingOptions::sharp_interfaces = false the default.
TEST(LightCache, KeyFollowsTheInterfaces) {
  const Scene sharp = litScene();
  const Scene smoothed = parseScene(R"({
    "volume": {"bounds_min": [-2, -2, -2], "bounds_max": [2, 2, 2], "resolution": 6},
    "interfaces": "smoothed",
    "materials": {"g": {"n": 1.5}},
    "objects": [{"shape": "sphere", "radius": 1, "material": "g"}],
    "lights": [{"type": "directional", "direction": [0, -1, 0], "irradiance": 2}]})",
                                    "cache-test.json");
  const VolumeSet vSharp = voxelize(sharp), vSmoothed = voxelize(smoothed);
  ASSERT_TRUE(sharpLightApplies(vSharp));
  ASSERT_FALSE(sharpLightApplies(vSmoothed));
  const LightingOptions o;
  for (bool reference : {false, true}) {
    const uint64_t key = lightCacheKey(sharp, vSharp, o, reference);
    EXPECT_NE(lightCacheKey(smoothed, vSmoothed, o, reference), key);
    LightingOptions off = o;
    off.sharp_interfaces = false;
    EXPECT_NE(lightCacheKey(sharp, vSharp, off, reference), key);
    // Off, or a smoothed scene: the light takes the smoothed path either way.
    EXPECT_EQ(lightCacheKey(smoothed, vSmoothed, off, reference),
              lightCacheKey(smoothed, vSmoothed, o, reference));
  }
}

TEST(LightCache, ACorruptedEntryIsRefusedWithANotice) {
  TempDir dir;
  const Scene scene = litScene();
  VolumeSet stored = voxelize(scene);
  fillLight(stored);
  const uint64_t key = lightCacheKey(scene, stored, LightingOptions{}, false);
  ASSERT_EQ(saveLightCache(dir.path(), key, stored), "");
  const std::filesystem::path entry = lightCachePath(dir.path(), key);
  ASSERT_TRUE(std::filesystem::is_regular_file(entry));
  {
    // One byte of the payload (the last float of the flux volume) changed, the size unchanged.
    std::fstream f(entry, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(-1, std::ios::end);
    f.put('\x7f');
  }
  VolumeSet loaded = voxelize(scene);
  std::string notice;
  EXPECT_FALSE(loadLightCache(dir.path(), key, loaded, &notice));
  EXPECT_NE(notice.find("checksum mismatch"), std::string::npos) << notice;
  EXPECT_EQ(notice.find('\n'), std::string::npos) << "one line: " << notice;
  EXPECT_TRUE(loaded.light_fluence.empty());  // nothing half-read
  EXPECT_TRUE(loaded.light_flux.empty());
}

// An entry of the wrong size is refused by its size alone: a sparse 50 GB file is not read.
TEST(LightCache, AnEntryOfTheWrongSizeIsRefusedUnread) {
  TempDir dir;
  const Scene scene = litScene();
  VolumeSet stored = voxelize(scene);
  fillLight(stored);
  const uint64_t key = lightCacheKey(scene, stored, LightingOptions{}, false);
  ASSERT_EQ(saveLightCache(dir.path(), key, stored), "");
  const std::filesystem::path entry = lightCachePath(dir.path(), key);
  ASSERT_TRUE(std::filesystem::is_regular_file(entry));
  ASSERT_EQ(::truncate(entry.c_str(), off_t(50) << 30), 0);
  VolumeSet loaded = voxelize(scene);
  std::string notice;
  const auto start = std::chrono::steady_clock::now();
  EXPECT_FALSE(loadLightCache(dir.path(), key, loaded, &notice));
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(1));
  EXPECT_NE(notice.find("wrong size"), std::string::npos) << notice;
  EXPECT_TRUE(loaded.light_fluence.empty());
}

}  // namespace
}  // namespace eikon::test
