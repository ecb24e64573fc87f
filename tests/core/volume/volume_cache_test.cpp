// The cache of voxelised volumes (core/volume/volume_cache.h): an entry gives
// back the voxeliser's volume bit for bit (every array, every flag, the boundary field's shapes
// and media rebuilt from the scene), the key follows what the voxeliser reads and ignores what it
// does not, and a random, truncated, bit-flipped, foreign, misnamed or oversized file is ignored
// with one notice — never read as a volume, never a crash — and replaced by the next save. The
// CLI's use of it: tests/apps/startup_cli_test.cpp.
#include "core/volume/volume_cache.h"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <variant>
#include <vector>

#include "core/io/build_id.h"
#include "core/io/cache_limit.h"
#include "tests/core/file_support.h"
#include "tests/core/scene_support.h"

namespace eikon::test {
namespace {

using eikon::test::put;
using eikon::test::slurp;

namespace fs = std::filesystem;

// Sharp interfaces, a uniaxial crystal over a glass box with attenuation and an albedo: every
// array of a VolumeSet is present (e-mode fields, axis, scatter, the boundary field).
constexpr const char* kCrystal = R"({
  "volume": {"bounds_min": [-3, -3, -3], "bounds_max": [3, 3, 3], "resolution": 10},
  "materials": {
    "glass": {"n": 1.5, "attenuation_per_mm": [0.1, 0.2, 0.3], "albedo": 0.5},
    "calcite": {"n_o": 1.658, "n_e": 1.486, "optic_axis": [0, 1, 0]}},
  "objects": [{"shape": "box", "size": [4, 1, 4], "center": [0, -1.5, 0], "material": "glass"},
              {"shape": "sphere", "radius": 1.2, "material": "calcite"}]})";

// Smoothed interfaces, one glass sphere: no boundary field, the dispersion fields all zero.
constexpr const char* kSmoothed = R"({
  "interfaces": "smoothed",
  "volume": {"bounds_min": [-2, -2, -2], "bounds_max": [2, 2, 2], "resolution": 8},
  "materials": {"g": {"n": 1.5}},
  "objects": [{"shape": "sphere", "radius": 1, "material": "g"}]})";

Scene scene(const char* json) { return parseScene(json, "volume-cache-test.json"); }

template <typename T>
::testing::AssertionResult sameBits(const std::vector<T>& a, const std::vector<T>& b,
                                    const char* what) {
  if (a.size() != b.size())
    return ::testing::AssertionFailure() << what << ": " << a.size() << " vs " << b.size();
  if (!a.empty() && std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) != 0)
    return ::testing::AssertionFailure() << what << ": the bytes differ";
  return ::testing::AssertionSuccess();
}

/// Every part of two volumes, bit for bit (the boundary's shapes by kind, pose and geometry kind).
void expectSameVolume(const VolumeSet& a, const VolumeSet& b) {
  EXPECT_EQ(a.grid.dims, b.grid.dims);
  EXPECT_EQ(a.grid.origin, b.grid.origin);
  EXPECT_EQ(a.grid.extent, b.grid.extent);
  EXPECT_EQ(a.grid.h, b.grid.h);
  EXPECT_EQ(a.uniaxial, b.uniaxial);
  EXPECT_EQ(a.dispersive, b.dispersive);
  EXPECT_EQ(a.attenuating, b.attenuating);
  EXPECT_EQ(a.emissive, b.emissive);
  EXPECT_EQ(a.opaque, b.opaque);
  EXPECT_EQ(a.scattering, b.scattering);
  EXPECT_EQ(a.ambient_index, b.ambient_index);
  EXPECT_EQ(a.skip_cap, b.skip_cap);
  for (int m = 0; m < 2; ++m) {
    for (int c = 0; c < 3; ++c) EXPECT_TRUE(sameBits(a.index[m][c], b.index[m][c], "index"));
    EXPECT_TRUE(sameBits(a.medium[m], b.medium[m], "medium"));
  }
  EXPECT_TRUE(sameBits(a.emission, b.emission, "emission"));
  EXPECT_TRUE(sameBits(a.axis, b.axis, "axis"));
  EXPECT_TRUE(sameBits(a.scatter, b.scatter, "scatter"));
  EXPECT_TRUE(sameBits(a.light_fluence, b.light_fluence, "light fluence"));
  EXPECT_TRUE(sameBits(a.boundary.region, b.boundary.region, "boundary region"));
  EXPECT_TRUE(sameBits(a.boundary.distance, b.boundary.distance, "boundary distance"));
  EXPECT_EQ(a.boundary.cap, b.boundary.cap);
  EXPECT_EQ(a.boundary.grid.dims, b.boundary.grid.dims);
  EXPECT_EQ(a.boundary.grid.h, b.boundary.grid.h);
  EXPECT_EQ(a.boundary.medium, b.boundary.medium);
  EXPECT_EQ(a.boundary.media, b.boundary.media);
  EXPECT_EQ(a.boundary.convex_apart, b.boundary.convex_apart);
  ASSERT_EQ(a.boundary.shapes.size(), b.boundary.shapes.size());
  for (size_t i = 0; i < a.boundary.shapes.size(); ++i) {
    EXPECT_EQ(a.boundary.shapes[i].kind(), b.boundary.shapes[i].kind());
    EXPECT_EQ(a.boundary.shapes[i].center(), b.boundary.shapes[i].center());
    EXPECT_EQ(a.boundary.shapes[i].geometry().index(), b.boundary.shapes[i].geometry().index());
  }
  ASSERT_EQ(a.media.regions.size(), b.media.regions.size());
  for (size_t r = 0; r < a.media.regions.size(); ++r) {
    EXPECT_EQ(a.media.regions[r].medium, b.media.regions[r].medium);
    EXPECT_EQ(a.media.regions[r].n_o.coeff, b.media.regions[r].n_o.coeff);
    EXPECT_EQ(a.media.regions[r].n_e.coeff, b.media.regions[r].n_e.coeff);
    EXPECT_EQ(a.media.regions[r].axis, b.media.regions[r].axis);
    EXPECT_EQ(a.media.regions[r].sigma_o, b.media.regions[r].sigma_o);
  }
}

class VolumeCache : public ::testing::Test {
 protected:
  void SetUp() override {
    if (codeBuildId().empty()) GTEST_SKIP() << "this test binary has no build id";
  }
  TempDir dir_;
};

TEST_F(VolumeCache, TheBinaryHasABuildId) {
  const std::string id = codeBuildId();
  EXPECT_GE(id.size(), 16u);
  EXPECT_EQ(id.find_first_not_of("0123456789abcdef"), std::string::npos) << id;
}

TEST_F(VolumeCache, AnEntryGivesBackTheVoxelisedVolumeBitForBit) {
  for (const char* json : {kCrystal, kSmoothed}) {
    const Scene s = scene(json);
    const VolumeSet voxelised = voxelize(s);
    const uint64_t key = volumeCacheKey(s);
    ASSERT_NE(key, 0u);
    VolumeSet loaded;
    std::string notice;
    EXPECT_FALSE(loadVolumeCache(dir_.path(), key, s, loaded, &notice));  // none yet: quietly
    EXPECT_EQ(notice, "");
    ASSERT_EQ(saveVolumeCache(dir_.path(), key, voxelised), "");
    ASSERT_TRUE(loadVolumeCache(dir_.path(), key, s, loaded, &notice)) << notice;
    EXPECT_EQ(notice, "");
    expectSameVolume(loaded, voxelised);
  }
  // What the crystal scene must have exercised: every kind of array.
  const VolumeSet v = voxelize(scene(kCrystal));
  EXPECT_TRUE(v.uniaxial && v.attenuating && v.scattering && !v.boundary.empty());
}

// An array of zero bits is stored as a flag: the smoothed sphere's file is smaller than its
// arrays (the dispersion fields B and C and the attenuation are zero), and still loads as zeros.
TEST_F(VolumeCache, ZeroArraysAreStoredAsAFlag) {
  const Scene s = scene(kSmoothed);
  const VolumeSet v = voxelize(s);
  ASSERT_EQ(saveVolumeCache(dir_.path(), volumeCacheKey(s), v), "");
  const size_t arrays = 5 * v.grid.count() * sizeof(glm::vec4);  // index A-C, medium, emission
  EXPECT_LT(fs::file_size(volumeCachePath(dir_.path(), volumeCacheKey(s))), arrays * 3 / 5);
}

TEST_F(VolumeCache, KeyFollowsWhatTheVoxeliserReads) {
  const Scene base = scene(kCrystal);
  const uint64_t key = volumeCacheKey(base);
  EXPECT_EQ(volumeCacheKey(scene(kCrystal)), key);  // the same content, parsed again
  auto changed = [&](auto edit) {
    Scene s = base;
    edit(s);
    return volumeCacheKey(s);
  };
  EXPECT_NE(changed([](Scene& s) { s.volume.resolution = 11; }), key);
  EXPECT_NE(changed([](Scene& s) { s.volume.smoothing_voxels = 1.0; }), key);
  EXPECT_NE(changed([](Scene& s) { s.volume.bounds_max.x = 4.0; }), key);
  EXPECT_NE(changed([](Scene& s) { s.ambient_index = 1.33; }), key);
  EXPECT_NE(changed([](Scene& s) { s.interfaces = Scene::Interfaces::Smoothed; }), key);
  EXPECT_NE(changed([](Scene& s) { s.materials.at("glass").n_o = Dispersion::constant(1.51); }),
            key);
  EXPECT_NE(changed([](Scene& s) { s.materials.at("glass").albedo.x = 0.25; }), key);
  EXPECT_NE(changed([](Scene& s) { s.materials.at("calcite").optic_axis = glm::dvec3(1, 0, 0); }),
            key);
  EXPECT_NE(changed([](Scene& s) { s.objects[1].material = "glass"; }), key);
  EXPECT_NE(changed([](Scene& s) {
              s.objects[1].shape =
                  Shape("sphere", SphereShape{1.3}, glm::dvec3(0.0), glm::dvec3(0.0));
            }),
            key);
  EXPECT_NE(changed([](Scene& s) { std::swap(s.objects[0], s.objects[1]); }), key);
  // What the voxeliser does not read.
  EXPECT_EQ(changed([](Scene& s) { s.camera.position.z = -99.0; }), key);
  EXPECT_EQ(changed([](Scene& s) { s.camera.width = 64; }), key);
  EXPECT_EQ(changed([](Scene& s) { s.environment.squares = 3; }), key);
  EXPECT_EQ(changed([](Scene& s) { s.lights.push_back(Light{}); }), key);
}

// Each damaged file is refused with one line naming it and saying why; the volume passed in is
// left as it was; the next save replaces the file with a good entry.
TEST_F(VolumeCache, DamagedFilesAreIgnoredWithOneNoticeAndReplaced) {
  const Scene s = scene(kCrystal);
  const VolumeSet good = voxelize(s);
  const uint64_t key = volumeCacheKey(s);
  const fs::path file = volumeCachePath(dir_.path(), key);
  ASSERT_EQ(saveVolumeCache(dir_.path(), key, good), "");
  const std::string bytes = slurp(file);
  ASSERT_GT(bytes.size(), 200u);

  std::mt19937 rng(7);
  std::string random(bytes.size(), '\0');
  for (char& c : random) c = char(rng());
  std::string header_flip = bytes, payload_flip = bytes, late_flip = bytes;
  header_flip[17] ^= 0x10;              // the key
  payload_flip[56 + 4] ^= 0x01;         // a flag of the payload
  late_flip[bytes.size() - 3] ^= 0x40;  // the last array's data
  std::string foreign = bytes;
  std::memcpy(foreign.data(), "EIKLIGHT", 8);
  std::string oversized = bytes;
  const uint64_t huge = kMaxVolumeEntryBytes + 1;
  std::memcpy(oversized.data() + 40, &huge, 8);  // the payload size
  const std::vector<std::pair<std::string, std::string>> damaged = {
      {"random bytes", random},
      {"empty", ""},
      {"truncated header", bytes.substr(0, 30)},
      {"truncated payload", bytes.substr(0, bytes.size() / 2)},
      {"one byte short", bytes.substr(0, bytes.size() - 1)},
      {"a byte too many", bytes + "x"},
      {"bit flip in the header", header_flip},
      {"bit flip in the flags", payload_flip},
      {"bit flip in the data", late_flip},
      {"foreign magic", foreign},
      {"oversized", oversized}};
  for (const auto& [what, content] : damaged) {
    SCOPED_TRACE(what);
    put(file, content);
    VolumeSet v;
    v.ambient_index = 7.0;  // a marker: a refused load leaves the volume alone
    std::string notice;
    EXPECT_FALSE(loadVolumeCache(dir_.path(), key, s, v, &notice));
    EXPECT_EQ(v.ambient_index, 7.0);
    EXPECT_TRUE(v.index[0][0].empty());
    EXPECT_EQ(notice.rfind("volume cache '" + file.string() + "' ignored: ", 0), 0u) << notice;
    EXPECT_EQ(notice.find('\n'), std::string::npos) << notice;
    ASSERT_EQ(saveVolumeCache(dir_.path(), key, good), "");
    EXPECT_EQ(slurp(file), bytes);
  }
  // An entry of another scene copied under this one's name does not match its name.
  const Scene other = scene(kSmoothed);
  ASSERT_EQ(saveVolumeCache(dir_.path(), volumeCacheKey(other), voxelize(other)), "");
  fs::copy_file(volumeCachePath(dir_.path(), volumeCacheKey(other)), file,
                fs::copy_options::overwrite_existing);
  VolumeSet v;
  std::string notice;
  EXPECT_FALSE(loadVolumeCache(dir_.path(), key, s, v, &notice));
  EXPECT_NE(notice.find("does not match its name"), std::string::npos) << notice;
}

// An entry whose size disagrees with its header is refused by the sizes alone: a sparse 50 GB
// file behind a valid header is not read.
TEST_F(VolumeCache, ASparseHugeEntryIsIgnoredUnread) {
  const Scene s = scene(kCrystal);
  const uint64_t key = volumeCacheKey(s);
  const fs::path file = volumeCachePath(dir_.path(), key);
  ASSERT_EQ(saveVolumeCache(dir_.path(), key, voxelize(s)), "");
  ASSERT_EQ(::truncate(file.c_str(), off_t(50) << 30), 0);
  VolumeSet v;
  std::string notice;
  const auto start = std::chrono::steady_clock::now();
  EXPECT_FALSE(loadVolumeCache(dir_.path(), key, s, v, &notice));
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(1));
  EXPECT_NE(notice.find("ignored: wrong size"), std::string::npos) << notice;
}

// A pipe in an entry's place is not opened (a read would wait for a writer: renders hung), and
// the entry saved after it is refused there rather than replacing the pipe.
TEST_F(VolumeCache, APipeInPlaceOfAnEntryIsIgnoredNotRead) {
  const Scene s = scene(kCrystal);
  const uint64_t key = volumeCacheKey(s);
  const fs::path file = volumeCachePath(dir_.path(), key);
  ASSERT_EQ(::mkfifo(file.c_str(), 0600), 0);
  VolumeSet v;
  std::string notice;
  EXPECT_FALSE(loadVolumeCache(dir_.path(), key, s, v, &notice));
  EXPECT_NE(notice.find("ignored: it is not a regular file"), std::string::npos) << notice;
  EXPECT_NE(saveVolumeCache(dir_.path(), key, voxelize(s)), "");
  EXPECT_EQ(fs::status(file).type(), fs::file_type::fifo);
}

// Another format version is not an error: replaced quietly, as the light cache does.
TEST_F(VolumeCache, AnotherFormatVersionIsReplacedQuietly) {
  const Scene s = scene(kSmoothed);
  const uint64_t key = volumeCacheKey(s);
  ASSERT_EQ(saveVolumeCache(dir_.path(), key, voxelize(s)), "");
  const fs::path file = volumeCachePath(dir_.path(), key);
  std::string bytes = slurp(file);
  const uint64_t format = 999;
  std::memcpy(bytes.data() + 8, &format, 8);
  put(file, bytes);
  VolumeSet v;
  std::string notice;
  EXPECT_FALSE(loadVolumeCache(dir_.path(), key, s, v, &notice));
  EXPECT_EQ(notice, "");
}

// One cap: after a save the folder's entries of every kind together are kept under the folder's
// cap (core/io/cache_limit.h), least recently used first whatever their kind: an old light entry
// goes before an older volume's neighbour, and a volume goes while a more recently used light entry
// stays. Never the entry just written, never other files. (With a cap of the volume entries' own,
// the old light entry outlived the volumes and the folder held more than the cap.)
TEST_F(VolumeCache, TheFoldersCapIsTheOnlyCap) {
  std::vector<Scene> scenes;  // three entries of one size: spheres of other radii
  for (double radius : {1.0, 0.9, 0.8}) {
    Scene s = scene(kSmoothed);
    s.objects[0].shape = Shape("sphere", SphereShape{radius}, glm::dvec3(0.0), glm::dvec3(0.0));
    scenes.push_back(s);
  }
  const fs::path oldLight = dir_.path() / "light-0000000000000001.bin";
  const fs::path newLight = dir_.path() / "light-0000000000000002.bin";
  const fs::path other = dir_.path() / "notes.txt";
  put(oldLight, "an old light entry");
  put(newLight, "a recent light entry");
  put(other, "not a cache entry");
  std::vector<fs::path> files;
  uint64_t sizes = 0;
  for (size_t i = 0; i < 2; ++i) {
    ASSERT_EQ(saveVolumeCache(dir_.path(), volumeCacheKey(scenes[i]), voxelize(scenes[i])), "");
    files.push_back(volumeCachePath(dir_.path(), volumeCacheKey(scenes[i])));
    sizes += fs::file_size(files.back());
  }
  // Use order, oldest first: the old light entry, volume 0, volume 1, the recent light entry.
  const auto now = fs::last_write_time(files[1]);
  fs::last_write_time(oldLight, now - std::chrono::hours(3));
  fs::last_write_time(files[0], now - std::chrono::hours(2));
  fs::last_write_time(files[1], now - std::chrono::hours(1));
  fs::last_write_time(newLight, now);
  // Room for two volumes and the recent light entry: the old light entry and volume 0 go.
  const uint64_t cap = sizes + fs::file_size(newLight);
  const VolumeSet third = voxelize(scenes[2]);
  ASSERT_EQ(saveVolumeCache(dir_.path(), volumeCacheKey(scenes[2]), third, cap), "");
  EXPECT_EQ(fs::file_size(volumeCachePath(dir_.path(), volumeCacheKey(scenes[2]))), sizes / 2);
  EXPECT_FALSE(fs::exists(oldLight));
  EXPECT_FALSE(fs::exists(files[0]));
  EXPECT_TRUE(fs::exists(files[1]));
  EXPECT_TRUE(fs::exists(newLight));
  EXPECT_TRUE(fs::exists(volumeCachePath(dir_.path(), volumeCacheKey(scenes[2]))));
  EXPECT_TRUE(fs::exists(other));
}

// The default cap of a save is the folder's, EIKON_CACHE_MAX_MB (0: only the entry just written
// stays), not one of the volume cache's own.
TEST_F(VolumeCache, ASaveKeepsToEikonCacheMaxMb) {
  Scene s = scene(kSmoothed);
  const fs::path light = dir_.path() / "light-0000000000000001.bin";
  put(light, "a light entry");
  ASSERT_EQ(saveVolumeCache(dir_.path(), volumeCacheKey(s), voxelize(s)), "");
  EXPECT_TRUE(fs::exists(light));  // the default 1 GiB holds both
  const char* before = std::getenv("EIKON_CACHE_MAX_MB");
  const std::string saved = before ? before : "";
  ::setenv("EIKON_CACHE_MAX_MB", "0", 1);
  s.objects[0].shape = Shape("sphere", SphereShape{0.7}, glm::dvec3(0.0), glm::dvec3(0.0));
  const std::string err = saveVolumeCache(dir_.path(), volumeCacheKey(s), voxelize(s));
  if (before)
    ::setenv("EIKON_CACHE_MAX_MB", saved.c_str(), 1);
  else
    ::unsetenv("EIKON_CACHE_MAX_MB");
  ASSERT_EQ(err, "");
  size_t entries = 0;
  for (const auto& e : fs::directory_iterator(dir_.path()))
    entries += isCacheEntryName(e.path().filename().string()) ? 1 : 0;
  EXPECT_EQ(entries, 1u);
  EXPECT_TRUE(fs::exists(volumeCachePath(dir_.path(), volumeCacheKey(s))));
}

}  // namespace
}  // namespace eikon::test
