#include "core/volume/volume_cache.h"

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <stdexcept>
#include <system_error>
#include <utility>
#include <variant>
#include <vector>

#include "core/io/atomic_write.h"
#include "core/io/build_id.h"
#include "core/io/cache_limit.h"
#include "core/scene/mesh.h"
#include "core/volume/media.h"

namespace eikon {
namespace {

namespace fs = std::filesystem;

constexpr uint64_t kFormat = 1;
constexpr char kMagic[8] = {'E', 'I', 'K', 'V', 'O', 'X', 'E', 'L'};

struct Header {
  char magic[8];
  uint64_t format, key;
  int32_t dims[3], pad;
  uint64_t payload_bytes, checksum;
};
static_assert(sizeof(Header) == 56, "the header is written as it is laid out");

// ---------------------------------------------------------------- hashing

/// A 64-bit hash of a byte range in four independent lanes (xxHash64's round and constants), so
/// that a checksum of a 128³ volume's ~100 MB costs a few hundredths of a second, not a tenth.
uint64_t hashBytes(const void* data, size_t n, uint64_t seed = 0) {
  constexpr uint64_t P1 = 0x9E3779B185EBCA87ULL, P2 = 0xC2B2AE3D27D4EB4FULL,
                     P3 = 0x165667B19E3779F9ULL, P4 = 0x85EBCA77C2B2AE63ULL,
                     P5 = 0x27D4EB2F165667C5ULL;
  auto rotl = [](uint64_t x, int r) { return (x << r) | (x >> (64 - r)); };
  auto round = [&](uint64_t acc, uint64_t w) { return rotl(acc + w * P2, 31) * P1; };
  const auto* p = static_cast<const unsigned char*>(data);
  uint64_t lane[4] = {seed + P1 + P2, seed + P2, seed, seed - P1};
  size_t i = 0;
  for (; i + 32 <= n; i += 32)
    for (int l = 0; l < 4; ++l) {
      uint64_t w;
      std::memcpy(&w, p + i + 8 * l, 8);
      lane[l] = round(lane[l], w);
    }
  uint64_t h = rotl(lane[0], 1) + rotl(lane[1], 7) + rotl(lane[2], 12) + rotl(lane[3], 18);
  for (uint64_t l : lane) h = (h ^ round(0, l)) * P1 + P4;
  h += uint64_t(n);
  for (; i + 8 <= n; i += 8) {
    uint64_t w;
    std::memcpy(&w, p + i, 8);
    h = rotl(h ^ round(0, w), 27) * P1 + P4;
  }
  for (; i < n; ++i) h = rotl(h ^ (uint64_t(p[i]) * P5), 11) * P1;
  h ^= h >> 33;
  h *= P2;
  h ^= h >> 29;
  h *= P3;
  return h ^ (h >> 32);
}

/// The bytes of what is hashed, appended field by field (never a struct with padding).
class KeyBytes {
 public:
  template <typename T>
  void value(const T& v) {
    static_assert(std::is_arithmetic_v<T> || std::is_enum_v<T>);
    raw(&v, sizeof v);
  }
  void vec3(const glm::dvec3& v) {
    for (int a = 0; a < 3; ++a) value(v[a]);
  }
  void text(const std::string& s) {
    value(s.size());
    raw(s.data(), s.size());
  }
  void doubles(const std::vector<double>& v) {
    value(v.size());
    for (double d : v) value(d);
  }
  void optionalVec3(const std::optional<glm::dvec3>& v) {
    value(v.has_value());
    if (v) vec3(*v);
  }
  const std::string& bytes() const { return b_; }

 private:
  void raw(const void* p, size_t n) { b_.append(static_cast<const char*>(p), n); }
  std::string b_;
};

void hashDispersion(KeyBytes& k, const Dispersion& d) {
  k.value(d.kind());
  k.doubles(d.coefficients());
  k.doubles(d.sellmeierC());
  k.value(d.rangeNm().has_value());
  if (d.rangeNm()) k.doubles({(*d.rangeNm())[0], (*d.rangeNm())[1]});
}

void hashMaterial(KeyBytes& k, const std::string& name, const Material& m) {
  k.text(name);
  k.value(m.uniaxial);
  hashDispersion(k, m.n_o);
  hashDispersion(k, m.n_e);
  k.value(m.grin.type);
  k.value(m.grin.n0);
  k.vec3(m.grin.gradient);
  k.vec3(m.grin.origin);
  k.value(m.grin.radius);
  k.optionalVec3(m.optic_axis);
  for (const Attenuation* a : {&m.attenuation_o, &m.attenuation_e}) {
    k.vec3(a->rgb);
    k.doubles(a->wavelengths_nm);
    k.doubles(a->values);
  }
  k.value(m.biaxial);  // a biaxial crystal's tensor (the media table is cached)
  if (m.biaxial) {
    for (const Dispersion* d : {&m.n_alpha, &m.n_beta, &m.n_gamma}) hashDispersion(k, *d);
    k.vec3(m.alpha_axis);
    k.vec3(m.gamma_axis);
    for (const Attenuation* a : {&m.attenuation_alpha, &m.attenuation_beta, &m.attenuation_gamma}) {
      k.vec3(a->rgb);
      k.doubles(a->wavelengths_nm);
      k.doubles(a->values);
    }
  }
  k.vec3(m.emission);
  k.value(m.opacity);
  k.vec3(m.albedo);
  k.value(m.phase_g);
}

void hashShape(KeyBytes& k, const Shape& s) {
  k.text(s.kind());
  k.vec3(s.center());
  for (int c = 0; c < 3; ++c) k.vec3(s.rotation()[c]);
  const ShapeGeometry& g = s.geometry();
  k.value(g.index());
  if (const auto* sp = std::get_if<SphereShape>(&g)) {
    k.value(sp->radius);
  } else if (const auto* b = std::get_if<BoxShape>(&g)) {
    k.vec3(b->size);
  } else if (const auto* rb = std::get_if<RoundedBoxShape>(&g)) {
    k.vec3(rb->size);
    k.value(rb->radius);
  } else if (const auto* c = std::get_if<ConvexShape>(&g)) {
    k.value(c->planes.size());
    for (const Plane& p : c->planes) {
      k.vec3(p.normal);
      k.value(p.d);
    }
    k.value(c->bounding_radius);
  } else if (const auto* m = std::get_if<MeshShape>(&g)) {
    k.value(m->bounding_radius);
    k.value(m->distance != nullptr);
    if (m->distance) {  // the hierarchy follows from the mesh (its build is deterministic)
      k.value(m->distance->vertices().size());
      for (const glm::dvec3& v : m->distance->vertices()) k.vec3(v);
      k.value(m->distance->triangles().size());
      for (const auto& t : m->distance->triangles())
        for (uint32_t i : t) k.value(i);
    }
  }
}

// ---------------------------------------------------------------- the payload

/// f(array) for each array of a VolumeSet (const or not), in file order.
template <typename V, typename F>
void forEachArray(V& v, F&& f) {
  for (auto& mode : v.index)
    for (auto& a : mode) f(a);
  for (auto& m : v.medium) f(m);
  f(v.emission);
  f(v.axis);
  f(v.scatter);
  f(v.boundary.region);
  f(v.boundary.distance);
}

/// The flags and scalars of a volume, as stored.
struct Scalars {
  uint8_t flags[8];  // uniaxial, dispersive, attenuating, emissive, opaque, scattering, sharp, pad
  double ambient_index;
  int32_t skip_cap;
  float boundary_cap;
};
static_assert(sizeof(Scalars) == 24, "written as laid out");

Scalars scalarsOf(const VolumeSet& v) {
  Scalars s{};
  const bool flags[7] = {v.uniaxial, v.dispersive, v.attenuating,      v.emissive,
                         v.opaque,   v.scattering, !v.boundary.empty()};
  for (int i = 0; i < 7; ++i) s.flags[i] = flags[i] ? 1 : 0;
  s.ambient_index = v.ambient_index;
  s.skip_cap = v.skip_cap;
  s.boundary_cap = v.boundary.cap;
  return s;
}

/// One array's record: its element count (0 or the grid's voxel count) and whether every byte is
/// zero (then no data follows).
struct ArrayRecord {
  uint64_t count;
  uint64_t zero;
};

bool allZero(const void* data, size_t bytes) {
  const auto* p = static_cast<const unsigned char*>(data);
  static const unsigned char zeros[4096] = {};
  for (size_t i = 0; i < bytes; i += sizeof zeros)
    if (std::memcmp(p + i, zeros, std::min(sizeof zeros, bytes - i)) != 0) return false;
  return true;
}

/// The checksum of a payload: the hash of the scalars and, per array, its record and data hash.
class Checksum {
 public:
  explicit Checksum(const Scalars& s) { add(&s, sizeof s); }
  void array(const ArrayRecord& r, const void* data, size_t bytes) {
    add(&r, sizeof r);
    const uint64_t h = r.zero || bytes == 0 ? 0 : hashBytes(data, bytes);
    add(&h, sizeof h);
  }
  uint64_t digest() const { return hashBytes(b_.data(), b_.size(), kFormat); }

 private:
  void add(const void* p, size_t n) { b_.append(static_cast<const char*>(p), n); }
  std::string b_;
};

/// Which arrays a volume of these flags has (the voxeliser's shapes of a VolumeSet), in file order.
std::vector<bool> expectedArrays(const Scalars& s) {
  const bool uniaxial = s.flags[0], scattering = s.flags[5], sharp = s.flags[6];
  return {true,     true, true,     uniaxial,   uniaxial, uniaxial, true,
          uniaxial, true, uniaxial, scattering, sharp,    sharp};
}

}  // namespace

uint64_t volumeCacheKey(const Scene& scene) {
  const std::string build = codeBuildId();
  if (build.empty()) return 0;
  KeyBytes k;
  k.value(kFormat);
  k.text(build);
  const VolumeSpec& v = scene.volume;
  k.vec3(v.bounds_min);
  k.vec3(v.bounds_max);
  k.value(v.resolution);
  k.value(v.smoothing_voxels);
  k.value(v.smoothing);
  k.value(scene.ambient_index);
  k.value(scene.interfaces);
  k.value(scene.materials.size());
  for (const auto& [name, m] : scene.materials) hashMaterial(k, name, m);
  k.value(scene.objects.size());
  for (const SceneObject& o : scene.objects) {
    hashShape(k, o.shape);
    k.text(o.material);
    k.optionalVec3(o.optic_axis);
    k.value(o.radial_axis);
    k.optionalVec3(o.alpha_axis);
    k.optionalVec3(o.gamma_axis);
  }
  const uint64_t key = hashBytes(k.bytes().data(), k.bytes().size());
  return key == 0 ? 1 : key;  // 0 means "no key"
}

fs::path volumeCachePath(const fs::path& dir, uint64_t key) {
  char name[40];
  std::snprintf(name, sizeof name, "volume-%016llx.bin", static_cast<unsigned long long>(key));
  return dir / name;
}

bool loadVolumeCache(const fs::path& dir, uint64_t key, const Scene& scene, VolumeSet& volume,
                     std::string* notice) {
  if (dir.empty() || key == 0) return false;
  const fs::path path = volumeCachePath(dir, key);
  auto ignored = [&](const std::string& why) {
    if (notice)
      *notice = "volume cache '" + path.string() + "' ignored: " + why + "; voxelising again";
    return false;
  };
  std::error_code ec;
  // Opening a pipe for reading waits for a writer: a pipe put in the cache's place hung renders.
  const fs::file_type type = fs::status(path, ec).type();
  if (type == fs::file_type::not_found) return false;
  if (type != fs::file_type::regular) return ignored("it is not a regular file");
  std::ifstream in(path, std::ios::binary);
  if (!in) return false;
  const uint64_t file_bytes = fs::file_size(path, ec);
  if (ec) return ignored("cannot read its size");
  Header h{};
  in.read(reinterpret_cast<char*>(&h), sizeof h);
  if (in.gcount() >= 8 && std::memcmp(h.magic, kMagic, 8) != 0)
    return ignored("not a volume cache file");
  if (!in) return ignored("truncated header");
  if (h.format != kFormat) return false;  // another version of eikon wrote it: replaced quietly
  const Grid grid = makeGrid(scene.volume);
  if (h.key != key || h.dims[0] != grid.dims[0] || h.dims[1] != grid.dims[1] ||
      h.dims[2] != grid.dims[2])
    return ignored("its header does not match its name");
  if (h.payload_bytes > kMaxVolumeEntryBytes)
    return ignored("larger than " + std::to_string(kMaxVolumeEntryBytes >> 20) + " MiB");
  if (file_bytes != sizeof h + h.payload_bytes)
    return ignored(file_bytes < sizeof h + h.payload_bytes ? "truncated" : "wrong size");

  VolumeSet v;
  Scalars s{};
  in.read(reinterpret_cast<char*>(&s), sizeof s);
  if (!in) return ignored("truncated");
  // Each array is sized by the flags, never by a count read from the file, so that a bad count
  // cannot allocate; the records must agree.
  const std::vector<bool> expected = expectedArrays(s);
  Checksum sum(s);
  size_t next = 0;
  std::string bad;
  forEachArray(v, [&](auto& a) {
    if (!bad.empty()) return;
    a.resize(expected[next++] ? grid.count() : 0);
    ArrayRecord r{};
    in.read(reinterpret_cast<char*>(&r), sizeof r);
    if (in && (r.count != a.size() || r.zero > 1)) bad = "its arrays do not match its header";
    const size_t bytes = a.size() * sizeof(a[0]);
    if (in && bad.empty() && !r.zero)
      in.read(reinterpret_cast<char*>(a.data()), std::streamsize(bytes));
    if (!in && bad.empty()) bad = "truncated";
    if (bad.empty()) sum.array(r, a.data(), bytes);
  });
  if (!bad.empty()) return ignored(bad);
  if (in.peek() != std::char_traits<char>::eof()) return ignored("wrong size");
  if (sum.digest() != h.checksum) return ignored("checksum mismatch");

  v.grid = grid;
  v.uniaxial = s.flags[0];
  v.dispersive = s.flags[1];
  v.attenuating = s.flags[2];
  v.emissive = s.flags[3];
  v.opaque = s.flags[4];
  v.scattering = s.flags[5];
  v.ambient_index = s.ambient_index;
  v.skip_cap = s.skip_cap;
  if (s.flags[6]) {  // the metadata voxelize() derives from the scene, derived the same way
    std::vector<uint16_t> region = std::move(v.boundary.region);
    std::vector<float> distance = std::move(v.boundary.distance);
    v.boundary = boundaryFieldShapes(scene, grid);
    v.boundary.region = std::move(region);
    v.boundary.distance = std::move(distance);
    v.boundary.cap = s.boundary_cap;
    v.media = buildMediaTable(scene);
  }
  volume = std::move(v);
  touchCacheEntry(path);  // recently used: kept longest
  return true;
}

std::string saveVolumeCache(const fs::path& dir, uint64_t key, const VolumeSet& volume,
                            uint64_t max_cache_bytes) {
  if (dir.empty()) return "no cache directory (set EIKON_CACHE_DIR or HOME)";
  if (key == 0) return "this binary has no build id to key the volume cache with";
  const Scalars s = scalarsOf(volume);
  const std::vector<bool> expected = expectedArrays(s);
  Checksum sum(s);
  std::vector<std::pair<ArrayRecord, std::pair<const void*, size_t>>> parts;  // record, data
  uint64_t payload = sizeof s;
  bool shaped = true;
  forEachArray(volume, [&](const auto& a) {
    const size_t bytes = a.size() * sizeof(a[0]);
    shaped = shaped && a.size() == (expected[parts.size()] ? volume.grid.count() : 0);
    const ArrayRecord r{a.size(), !a.empty() && allZero(a.data(), bytes) ? 1u : 0u};
    sum.array(r, a.data(), bytes);
    parts.push_back({r, {a.data(), bytes}});
    payload += sizeof r + (r.zero ? 0 : bytes);
  });
  if (!shaped) return "the volume's arrays do not have the sizes its flags give; not cached";
  if (payload > kMaxVolumeEntryBytes) return {};  // too large to be worth keeping: not an error
  Header h{};
  std::memcpy(h.magic, kMagic, 8);
  h.format = kFormat;
  h.key = key;
  for (int a = 0; a < 3; ++a) h.dims[a] = volume.grid.dims[size_t(a)];
  h.payload_bytes = payload;
  h.checksum = sum.digest();
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) return "cannot create " + dir.string() + ": " + ec.message();
  const fs::path path = volumeCachePath(dir, key);
  try {
    // Atomic (core/io): a reader sees the old entry or the whole new one, never a partial file.
    writeFileAtomically(path, [&](const fs::path& tmp) {
      std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
      out.write(reinterpret_cast<const char*>(&h), sizeof h);
      out.write(reinterpret_cast<const char*>(&s), sizeof s);
      for (const auto& [r, a] : parts) {
        out.write(reinterpret_cast<const char*>(&r), sizeof r);
        if (!r.zero) out.write(static_cast<const char*>(a.first), std::streamsize(a.second));
      }
      out.close();
      if (!out) throw std::runtime_error("write failed (disk full?)");
    });
  } catch (const std::exception& e) {
    return e.what();
  }
  trimCacheDir(dir, path, max_cache_bytes);  // the cache folder's cap (core/io/cache_limit.h)
  return {};
}

}  // namespace eikon
