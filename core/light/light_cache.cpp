#include "core/light/light_cache.h"

#include <cstdio>
#include <cstring>
#include <fstream>
#include <system_error>
#include <vector>

#include "core/io/atomic_write.h"
#include "core/io/build_id.h"
#include "core/io/cache_dir.h"
#include "core/io/cache_limit.h"
#include "core/light/lighting.h"
#include "core/volume/media.h"

namespace eikon {
namespace {

constexpr uint64_t kFormat = 2;  // 2: a checksum of the payload in the header
constexpr char kMagic[8] = {'E', 'I', 'K', 'L', 'I', 'G', 'H', 'T'};

/// Word-wise 64-bit hash (FNV-1a constants, one 64-bit word per round, murmur finaliser).
class Hasher {
 public:
  void bytes(const void* data, size_t n) {
    const auto* p = static_cast<const unsigned char*>(data);
    size_t i = 0;
    for (; i + 8 <= n; i += 8) {
      uint64_t w;
      std::memcpy(&w, p + i, 8);
      word(w);
    }
    uint64_t tail = 0;
    std::memcpy(&tail, p + i, n - i);
    word(tail ^ (uint64_t(n) << 56));
  }
  template <typename T>
  void value(const T& v) {
    bytes(&v, sizeof v);
  }
  template <typename T>
  void vec(const std::vector<T>& v) {
    value(v.size());
    if (!v.empty()) bytes(v.data(), v.size() * sizeof(T));
  }
  uint64_t digest() const {
    uint64_t x = h_;
    x ^= x >> 33;
    x *= 0xff51afd7ed558ccdULL;
    x ^= x >> 33;
    x *= 0xc4ceb9fe1a85ec53ULL;
    return x ^ (x >> 33);
  }

 private:
  void word(uint64_t w) { h_ = (h_ ^ w) * 0x100000001b3ULL + (h_ >> 29); }
  uint64_t h_ = 0xcbf29ce484222325ULL;
};

/// The header's checksum of the two light volumes (the hash above, over their bytes).
uint64_t payloadChecksum(const std::vector<glm::vec4>& fluence,
                         const std::vector<glm::vec4>& flux) {
  Hasher h;
  h.vec(fluence);
  h.vec(flux);
  return h.digest();
}

}  // namespace

std::filesystem::path lightCachePath(const std::filesystem::path& dir, uint64_t key) {
  char name[40];
  std::snprintf(name, sizeof name, "light-%016llx.bin", static_cast<unsigned long long>(key));
  return dir / name;
}

std::filesystem::path defaultLightCacheDir() { return defaultCacheDir(); }

uint64_t lightCacheKey(const Scene& scene, const VolumeSet& v, const LightingOptions& o,
                       bool reference) {
  Hasher h;
  h.value(kFormat);
  // The code that simulated it (as the volume cache keys its entries): a rebuilt eikon whose
  // simulator changed must not read the former one's light (it did: after torn patches became
  // pencils, renders kept the fans from the cache).
  const std::string build = codeBuildId();
  h.value(build.size());
  h.bytes(build.data(), build.size());
  h.value(reference);
  h.value(v.grid.dims);
  h.value(v.grid.origin);
  h.value(v.grid.h);
  h.value(v.ambient_index);
  for (const auto& mode : v.index)
    for (const auto& f : mode) h.vec(f);
  for (const auto& m : v.medium) h.vec(m);
  h.vec(v.axis);
  h.vec(v.scatter);
  h.value(scene.lights.size());
  for (const Light& l : scene.lights) {
    h.value(l.type);
    h.value(l.direction);
    h.value(l.position);
    h.value(l.irradiance);
    h.value(l.beam_radius);
    h.value(l.cone_half_angle_deg);
    h.vec(l.spectrum_nm);
    h.vec(l.spectrum_power);
  }
  const WavefrontSettings& s = o.wave;
  h.value(o.bands);
  h.value(o.smoothing_voxels);
  h.value(s.dt);
  h.value(s.max_steps);
  h.value(s.min_energy_fraction);
  h.value(s.split_span_voxels);
  h.value(s.split_halves);
  h.value(s.seed_span_voxels);
  h.value(s.splat);
  h.value(s.max_patches);
  h.value(s.point_radius);
  h.value(s.point_cells_per_face);
  h.value(s.skip_empty);
  h.value(s.pass_caustics);
  h.value(s.beam_min_cells);
  // Sharp interfaces: which path the light took, and what it refracted at (the
  // boundary field and the media); a smoothed entry must not serve a sharp scene.
  const bool sharp = o.sharp_interfaces && sharpLightApplies(v);
  h.value(sharp);
  if (sharp) {
    h.value(o.max_reflection_generations);
    h.vec(v.boundary.region);
    h.vec(v.boundary.distance);
    h.vec(packMediaTable(v.media));
  }
  return h.digest();
}

bool loadLightCache(const std::filesystem::path& dir, uint64_t key, VolumeSet& volume,
                    std::string* notice) {
  if (dir.empty()) return false;
  const std::filesystem::path path = lightCachePath(dir, key);
  auto corrupted = [&](const std::string& why) {
    if (notice) *notice = path.string() + " is corrupted (" + why + "); simulating the light again";
    return false;
  };
  // Opening a pipe for reading waits for a writer: only a regular file is read.
  std::error_code ec;
  const auto type = std::filesystem::status(path, ec).type();
  if (type == std::filesystem::file_type::not_found) return false;
  if (type != std::filesystem::file_type::regular) return corrupted("not a regular file");
  std::ifstream in(path, std::ios::binary);
  if (!in) return false;
  char magic[8];
  uint64_t format = 0, stored_key = 0, checksum = 0;
  std::array<int, 3> dims{};
  in.read(magic, 8);
  in.read(reinterpret_cast<char*>(&format), sizeof format);
  if (!in || std::memcmp(magic, kMagic, 8) != 0) return corrupted("not a light cache file");
  if (format != kFormat) return false;  // another version of eikon wrote it: replaced quietly
  in.read(reinterpret_cast<char*>(&stored_key), sizeof stored_key);
  in.read(reinterpret_cast<char*>(dims.data()), sizeof dims);
  in.read(reinterpret_cast<char*>(&checksum), sizeof checksum);
  if (!in) return corrupted("truncated header");
  if (stored_key != key || dims != volume.grid.dims)
    return corrupted("header does not match its name");
  const size_t N = volume.grid.count();
  // The size from the file system before any payload is allocated or read: a file of another size
  // (a sparse 50 GB one, say) is refused unread.
  const uintmax_t header_bytes =
      8 + sizeof format + sizeof stored_key + sizeof dims + sizeof checksum;
  if (std::filesystem::file_size(path, ec) != header_bytes + 2 * N * sizeof(glm::vec4) || ec)
    return corrupted("wrong size");
  std::vector<glm::vec4> fluence(N), flux(N);
  in.read(reinterpret_cast<char*>(fluence.data()), std::streamsize(N * sizeof(glm::vec4)));
  in.read(reinterpret_cast<char*>(flux.data()), std::streamsize(N * sizeof(glm::vec4)));
  if (!in || in.peek() != std::char_traits<char>::eof()) return corrupted("wrong size");
  if (payloadChecksum(fluence, flux) != checksum) return corrupted("checksum mismatch");
  volume.light_fluence = std::move(fluence);
  volume.light_flux = std::move(flux);
  touchCacheEntry(path);  // recently used: evicted last
  return true;
}

std::string saveLightCache(const std::filesystem::path& dir, uint64_t key,
                           const VolumeSet& volume) {
  if (dir.empty()) return "no cache directory (set EIKON_CACHE_DIR or HOME)";
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) return "cannot create " + dir.string() + ": " + ec.message();
  const std::filesystem::path final_path = lightCachePath(dir, key);
  try {
    // Atomic (core/io): a reader sees the old entry or the whole new one, never a partial file.
    writeFileAtomically(final_path, [&](const std::filesystem::path& tmp) {
      std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
      uint64_t format = kFormat,
               checksum = payloadChecksum(volume.light_fluence, volume.light_flux);
      out.write(kMagic, 8);
      out.write(reinterpret_cast<const char*>(&format), sizeof format);
      out.write(reinterpret_cast<const char*>(&key), sizeof key);
      out.write(reinterpret_cast<const char*>(volume.grid.dims.data()), sizeof volume.grid.dims);
      out.write(reinterpret_cast<const char*>(&checksum), sizeof checksum);
      out.write(reinterpret_cast<const char*>(volume.light_fluence.data()),
                std::streamsize(volume.light_fluence.size() * sizeof(glm::vec4)));
      out.write(reinterpret_cast<const char*>(volume.light_flux.data()),
                std::streamsize(volume.light_flux.size() * sizeof(glm::vec4)));
      out.close();
      if (!out) throw std::runtime_error("write failed (disk full?)");
    });
  } catch (const std::exception& e) {
    return e.what();
  }
  trimCacheDir(dir, final_path);  // the cache folder's cap (core/io/cache_limit.h)
  return {};
}

}  // namespace eikon
