#include "core/scene/scene.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <map>
#include <new>
#include <nlohmann/json.hpp>
#include <numbers>
#include <set>
#include <sstream>

#include "core/io/exr.h"
#include "core/io/text_file.h"
#include "core/scene/faceted.h"
#include "core/scene/gem_lighting.h"
#include "core/scene/limits.h"
#include "core/scene/material_library.h"
#include "core/scene/mesh.h"
#include "core/scene/scene_warnings.h"
#include "core/spectrum/illuminants.h"

namespace eikon {
namespace {

using json = nlohmann::json;
// Limits on what the scene may ask for, so that every derived quantity is representable:
// - positions and lengths within ±1e12 mm: distances are computed in double (squares ≤ 1e24, no
//   overflow) and a surface 1e12 mm from the origin is still placed to ~1e-4 mm;
// - a voxel edge of at least 1e-6 mm (1 nm, far below where geometric optics holds), so that 1/h
//   and the gradients the GPU stores are finite in float;
// - the volume within 65536 voxels of the origin: the GPU marches in single precision, whose
//   positions there resolve 2^-7 voxel (farther out the grid would be sampled off by whole voxels).
// Colours (emission, environment radiance, attenuation and albedo bands) and an environment's
// radiance after its intensity are at most 1e9, as an environment's intensity is: a radiance of
// 1e308 overflows to Inf in the float image (and Inf − Inf to NaN).
constexpr double kMaxColor = 1e9;
constexpr const char* kMaxColorText = "1e9";
constexpr double kMinVoxelMm = 1e-6;
constexpr double kMaxOffsetVoxels = 65536.0;
constexpr size_t kMaxPlanes = 4096;  // planes of one "planes" object
// Most faces of a convex mesh made a polyhedron: the exact path reads every record and plane of
// the shape table from its first 256 rows (core/volume/boundary.h kExactMaxRows; 6 rows are the
// shape's own record), and its plane loops cost a pass per face. A convex mesh of more faces stays
// a triangle mesh, whose crossings the exact path finds through its hierarchy in O(log n).
constexpr size_t kConvexMeshMaxFaces = 250;

std::string fmt(double v) {
  std::ostringstream s;
  s.precision(10);
  s << v;
  return s.str();
}

std::string point(const glm::dvec3& x) {
  return "(" + fmt(x.x) + ", " + fmt(x.y) + ", " + fmt(x.z) + ")";
}

std::string box(const VolumeSpec& v) {
  return point(v.bounds_min) + " to " + point(v.bounds_max) + " mm";
}

/// A JSON value with its location, for error messages that name file and path.
class Node {
 public:
  Node(const json& j, std::string path, const std::string& file)
      : j_(j), path_(std::move(path)), file_(file) {}

  [[noreturn]] void fail(const std::string& msg) const {
    throw SceneError(file_ + ": " + (path_.empty() ? "/" : path_) + ": " + msg);
  }
  const json& raw() const { return j_; }
  const std::string& path() const { return path_; }
  const std::string& file() const { return file_; }
  bool isObject() const { return j_.is_object(); }
  bool isNumber() const { return j_.is_number(); }
  bool isArray() const { return j_.is_array(); }
  bool isString() const { return j_.is_string(); }

  void requireObject() const {
    if (!j_.is_object()) fail("expected an object");
  }
  void allowKeys(std::initializer_list<const char*> keys) const {
    allowKeys(std::vector<std::string>(keys.begin(), keys.end()));
  }
  void allowKeys(const std::vector<std::string>& keys) const {
    requireObject();
    std::set<std::string> allowed(keys.begin(), keys.end());
    for (auto it = j_.begin(); it != j_.end(); ++it)
      if (!allowed.count(it.key())) {
        std::string list;
        for (const auto& k : allowed) list += (list.empty() ? "" : ", ") + k;
        throw SceneError(file_ + ": " + path_ + "/" + excerpt(it.key()) +
                         ": unknown key (allowed here: " + list + ")");
      }
  }
  bool has(const std::string& key) const { return j_.is_object() && j_.contains(key); }
  Node at(const std::string& key) const {
    requireObject();
    if (!j_.contains(key)) fail("missing required key '" + key + "'");
    return Node(j_.at(key), path_ + "/" + key, file_);
  }
  std::optional<Node> get(const std::string& key) const {
    if (!has(key)) return std::nullopt;
    return Node(j_.at(key), path_ + "/" + key, file_);
  }
  Node index(size_t i) const { return Node(j_.at(i), path_ + "/" + std::to_string(i), file_); }
  size_t size() const { return j_.size(); }

  double number() const {
    if (!j_.is_number()) fail("expected a number, got " + std::string(j_.type_name()));
    double v = j_.get<double>();
    if (!std::isfinite(v)) fail("must be finite");
    return v;
  }
  double number(double lo, double hi, bool lo_open = false, bool hi_open = false) const {
    double v = number();
    if (v < lo || (lo_open && v == lo) || v > hi || (hi_open && v == hi))
      fail("must be in " + std::string(lo_open ? "(" : "[") + fmt(lo) + ", " + fmt(hi) +
           (hi_open ? ")" : "]") + ", got " + fmt(v));
    return v;
  }
  double positive() const {
    double v = number();
    if (!(v > 0)) fail("must be > 0, got " + fmt(v));
    return v;
  }
  int integer(int lo, int hi) const {
    if (!j_.is_number_integer()) fail("expected an integer");
    if (j_.is_number_unsigned() && j_.get<unsigned long long>() > (unsigned long long)hi)
      fail("must be an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], got " +
           std::to_string(j_.get<unsigned long long>()));
    long long v = j_.get<long long>();
    if (v < lo || v > hi)
      fail("must be an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], got " +
           std::to_string(v));
    return int(v);
  }
  std::string string() const {
    if (!j_.is_string()) fail("expected a string");
    return j_.get<std::string>();
  }
  std::vector<double> numbers() const {
    if (!j_.is_array()) fail("expected an array of numbers");
    std::vector<double> v;
    for (size_t i = 0; i < j_.size(); ++i) v.push_back(index(i).number());
    return v;
  }
  glm::dvec3 vec3() const {
    if (!j_.is_array() || j_.size() != 3) fail("expected an array of 3 numbers");
    return {index(0).number(), index(1).number(), index(2).number()};
  }
  /// A number (grey) or [r, g, b], each in [0, kMaxColor].
  glm::dvec3 color() const {
    glm::dvec3 c = j_.is_number() ? glm::dvec3(number()) : vec3();
    if (c.x < 0 || c.y < 0 || c.z < 0) fail("must be non-negative");
    for (int k = 0; k < 3; ++k)
      if (c[k] > kMaxColor)
        (j_.is_number() ? *this : index(size_t(k)))
            .fail("must be at most " + std::string(kMaxColorText) + ", got " + fmt(c[k]));
    return c;
  }
  /// A point (mm) within ±kMaxCoordinateMm on every axis.
  glm::dvec3 position() const {
    glm::dvec3 v = vec3();
    for (int a = 0; a < 3; ++a)
      if (std::abs(v[a]) > kMaxCoordinateMm)
        index(size_t(a)).fail("must be within ±" + fmt(kMaxCoordinateMm) + " mm, got " + fmt(v[a]));
    return v;
  }
  /// A length (mm) in (0, kMaxCoordinateMm].
  double length() const {
    double v = positive();
    if (v > kMaxCoordinateMm)
      fail("must be at most " + fmt(kMaxCoordinateMm) + " mm, got " + fmt(v));
    return v;
  }
  glm::dvec3 unitVector() const {
    glm::dvec3 v = vec3();
    double len = glm::length(v);
    if (!(len > 1e-12) || !std::isfinite(len)) fail("must be a non-zero vector");
    return v / len;
  }

 private:
  const json& j_;
  std::string path_;
  const std::string& file_;
};

/// The file a "file" key names (`what`: "an EXR image"), relative to the scene's folder unless
/// absolute. An empty name and one holding a NUL byte (no file has one) are refused here.
std::filesystem::path namedFile(const Node& f, const std::string& what) {
  const std::string name = f.string();
  if (name.empty()) f.fail("expected the path of " + what + ", got an empty string");
  if (name.find('\0') != std::string::npos)
    f.fail("the file name '" + excerpt(name) + "' holds a NUL byte, which no file name can");
  std::filesystem::path p = name;
  if (p.is_relative()) p = std::filesystem::path(f.file()).parent_path() / p;
  return p;
}

// ------------------------------------------------------------------ materials
// Every refractive index a material defines lies in [kMinIndex, kMaxIndex] (core/scene/limits.h),
// as ambient_index and a gradient-index n0 do.

/// Why a Sellmeier model has no real index at `l` nm (n² ≤ 0 or a pole): a negative B, or a C
/// whose pole λ = √C lies in the checked window.
std::string sellmeierTrouble(const Dispersion& d, double l) {
  const std::vector<double>& b = d.coefficients();
  const std::vector<double>& c = d.sellmeierC();
  const double l2 = l * l * 1e-6;
  double n2 = 1.0;
  for (size_t i = 0; i < b.size(); ++i) n2 += b[i] * l2 / (l2 - c[i]);
  std::string why = "the Sellmeier sum gives n^2 = " + fmt(n2) + " at " + fmt(l) +
                    " nm: no real refractive index there";
  for (size_t i = 0; i < b.size(); ++i)
    if (c[i] >= 0.380 * 0.380 && c[i] <= 0.780 * 0.780)
      return why + " (C" + std::to_string(i + 1) + " = " + fmt(c[i]) + " um^2 puts a pole at " +
             fmt(1e3 * std::sqrt(c[i])) + " nm)";
  for (size_t i = 0; i < b.size(); ++i)
    if (b[i] < 0)
      return why + " (B" + std::to_string(i + 1) + " = " + fmt(b[i]) +
             " is negative: each B must be >= 0 for n^2 to stay above 1 away from the poles)";
  return why;
}

void checkIndexInRange(const Node& at, const Dispersion& d) {
  // An index outside [1, 10], infinite, or undefined (n² ≤ 0 at a Sellmeier pole or from a
  // negative term) anywhere in the visible window is an error (never clamped).
  for (double l = 380.0; l <= 780.0; l += 1.0) {
    const double n = d.index(l);
    if (std::isnan(n))
      at.fail(d.kind() == Dispersion::Kind::Sellmeier
                  ? sellmeierTrouble(d, l)
                  : "refractive index at " + fmt(l) +
                        " nm is not a number (the formula overflows)");
    if (std::isinf(n))
      at.fail("refractive index at " + fmt(l) +
              " nm is infinite (the formula overflows or has a pole there)");
    if (n < kMinIndex) at.fail("refractive index " + fmt(n) + " at " + fmt(l) + " nm is below 1");
    if (n > kMaxIndex)
      at.fail("refractive index " + fmt(n) + " at " + fmt(l) +
              " nm is above 10 (indices must be in [1, 10])");
  }
}

Dispersion parseDispersion(const Node& n, GrinProfile* grin) {
  if (n.isNumber()) {
    double v = n.number();
    if (v < kMinIndex) n.fail("refractive index must be >= 1, got " + fmt(v));
    if (v > kMaxIndex)
      n.fail("refractive index must be <= 10 (indices are in [1, 10]), got " + fmt(v));
    return Dispersion::constant(v);
  }
  if (!n.isObject())
    n.fail(
        "expected a number or an object {\"cauchy\": [...]} / {\"sellmeier\": [...]} / "
        "{\"conrady\": [...]}");
  n.allowKeys({"cauchy", "sellmeier", "conrady", "range_nm", "sigma", "linear", "luneburg",
               "maxwell_fisheye"});
  int kinds = int(n.has("cauchy")) + int(n.has("sellmeier")) + int(n.has("conrady")) +
              int(n.has("linear")) + int(n.has("luneburg")) + int(n.has("maxwell_fisheye"));
  if (kinds != 1)
    n.fail("give exactly one of cauchy, sellmeier, conrady, linear, luneburg, maxwell_fisheye");
  if (n.has("linear") || n.has("luneburg") || n.has("maxwell_fisheye")) {
    if (!grin)
      n.fail("gradient-index profiles are allowed only for isotropic materials (key \"n\")");
    if (auto l = n.get("linear")) {
      l->allowKeys({"n0", "gradient_per_mm", "origin"});
      grin->type = GrinProfile::Type::Linear;
      grin->n0 = l->at("n0").number(kMinIndex, kMaxIndex);
      grin->gradient = l->at("gradient_per_mm").vec3();
      grin->origin = l->get("origin") ? l->at("origin").position() : glm::dvec3(0.0);
    } else if (auto lu = n.get("luneburg")) {
      lu->allowKeys({"center", "radius"});
      grin->type = GrinProfile::Type::Luneburg;
      grin->origin = lu->at("center").position();
      grin->radius = lu->at("radius").length();
    } else {
      auto f = n.at("maxwell_fisheye");
      f.allowKeys({"center", "radius", "n0"});
      grin->type = GrinProfile::Type::MaxwellFisheye;
      grin->origin = f.at("center").position();
      grin->radius = f.at("radius").length();
      grin->n0 = f.at("n0").number(kMinIndex, kMaxIndex);
    }
    return Dispersion::constant(grin->type == GrinProfile::Type::Linear ? grin->n0 : 1.0);
  }
  Dispersion d;
  try {
    if (auto c = n.get("cauchy")) {
      auto v = c->numbers();
      if (v.empty() || v.size() > 6)
        c->fail("cauchy needs 1 to 6 coefficients [A, B, C, ...] (λ in µm), got " +
                std::to_string(v.size()));
      d = Dispersion::cauchy(v);
    } else if (auto cr = n.get("conrady")) {
      // n = n0 + A/λ + B/λ^3.5 (λ in µm); the renderer carries its Cauchy approximation.
      auto v = cr->numbers();
      if (v.size() != 3)
        cr->fail("conrady needs [n0, A, B] (n = n0 + A/λ + B/λ^3.5, λ in µm), got " +
                 std::to_string(v.size()) + " numbers");
      d = Dispersion::conrady(v[0], v[1], v[2]);
    } else {
      auto s = n.at("sellmeier");
      auto v = s.numbers();
      if (v.empty() || v.size() % 2 || v.size() > 12)
        s.fail("sellmeier needs [B1..Bk, C1..Ck] (k = 1..6, C in µm²), got " +
               std::to_string(v.size()) + " numbers");
      size_t k = v.size() / 2;
      d = Dispersion::sellmeier({v.begin(), v.begin() + long(k)}, {v.begin() + long(k), v.end()});
    }
    if (auto r = n.get("range_nm")) {
      auto v = r->numbers();
      if (v.size() != 2 || !(v[0] > 0 && v[1] > v[0]))
        r->fail("range_nm must be [lo, hi] with 0 < lo < hi");
      d.withRange(v[0], v[1]);
    }
  } catch (const std::invalid_argument& e) {
    n.fail(e.what());
  }
  checkIndexInRange(n, d);
  return d;
}

/// An attenuation: a number, [r, g, b] band values or a spectrum {"wavelength_nm", "per_mm"}.
/// `visible`: a spectrum must cover 380–780 nm (material files and biaxial keys: the renderer
/// samples the whole visible range, and a constant continuation beyond the data is a guess).
Attenuation parseAttenuation(const Node& n, bool visible = false) {
  Attenuation a;
  if (n.isObject()) {
    n.allowKeys({"wavelength_nm", "per_mm"});
    a.wavelengths_nm = n.at("wavelength_nm").numbers();
    a.values = n.at("per_mm").numbers();
    if (a.wavelengths_nm.size() != a.values.size() || a.values.empty())
      n.fail("wavelength_nm and per_mm must have the same non-zero length");
    for (size_t i = 0; i < a.values.size(); ++i) {
      if (!(a.wavelengths_nm[i] > 0))
        n.at("wavelength_nm")
            .index(i)
            .fail("wavelengths must be > 0 nm, got " + fmt(a.wavelengths_nm[i]));
      if (a.values[i] < 0) n.fail("attenuation must be >= 0");
      if (a.values[i] > kMaxColor)
        n.at("per_mm").index(i).fail("must be at most " + std::string(kMaxColorText) +
                                     " per mm, got " + fmt(a.values[i]));
      if (i && !(a.wavelengths_nm[i] > a.wavelengths_nm[i - 1]))
        n.fail("wavelength_nm must be strictly increasing");
    }
    if (visible && (a.wavelengths_nm.front() > 380.0 || a.wavelengths_nm.back() < 780.0))
      n.at("wavelength_nm")
          .fail("a spectrum must cover 380-780 nm, got " + fmt(a.wavelengths_nm.front()) + "-" +
                fmt(a.wavelengths_nm.back()) + " nm");
    return a;
  }
  a.rgb = n.color();
  return a;
}

constexpr std::array<const char*, 8> kBiaxialKeys = {"n_alpha",
                                                     "n_beta",
                                                     "n_gamma",
                                                     "alpha_axis",
                                                     "gamma_axis",
                                                     "attenuation_alpha_per_mm",
                                                     "attenuation_beta_per_mm",
                                                     "attenuation_gamma_per_mm"};

/// A biaxial material: n_alpha ≤ n_beta ≤ n_gamma at 380, 587.6 and 780 nm, alpha_axis and
/// gamma_axis (normalised, then orthogonal within 1e-6), attenuation per principal axis. The
/// isotropic and uniaxial keys are refused: one material is one kind of medium.
void parseBiaxial(const Node& m, Material& mat) {
  for (const char* k : {"n", "n_o", "n_e", "optic_axis", "attenuation_per_mm",
                        "attenuation_o_per_mm", "attenuation_e_per_mm"})
    if (m.has(k))
      m.at(k).fail(
          std::string("is an isotropic/uniaxial key; a biaxial material (n_alpha, "
                      "n_beta, n_gamma) takes alpha_axis, gamma_axis and "
                      "attenuation_alpha/beta/gamma_per_mm instead"));
  for (const char* k : {"n_alpha", "n_beta", "n_gamma", "alpha_axis", "gamma_axis"})
    if (!m.has(k)) m.fail(std::string("biaxial material is missing \"") + k + "\"");
  mat.biaxial = true;
  mat.n_alpha = parseDispersion(m.at("n_alpha"), nullptr);
  mat.n_beta = parseDispersion(m.at("n_beta"), nullptr);
  mat.n_gamma = parseDispersion(m.at("n_gamma"), nullptr);
  for (double l : {380.0, 587.6, 780.0}) {
    const double a = mat.n_alpha.index(l), b = mat.n_beta.index(l), g = mat.n_gamma.index(l);
    if (!(a <= b))
      m.at("n_beta").fail("must be >= n_alpha (n_alpha <= n_beta <= n_gamma): at " + fmt(l) +
                          " nm n_alpha = " + fmt(a) + ", n_beta = " + fmt(b));
    if (!(b <= g))
      m.at("n_gamma").fail("must be >= n_beta (n_alpha <= n_beta <= n_gamma): at " + fmt(l) +
                           " nm n_beta = " + fmt(b) + ", n_gamma = " + fmt(g));
  }
  mat.alpha_axis = m.at("alpha_axis").unitVector();
  mat.gamma_axis = m.at("gamma_axis").unitVector();
  const double c = glm::dot(mat.alpha_axis, mat.gamma_axis);
  if (std::abs(c) > 1e-6)
    m.at("gamma_axis")
        .fail(
            "must be orthogonal to alpha_axis (|cos| <= 1e-6 after normalising both), got cos "
            "= " +
            fmt(c));
  if (auto a = m.get("attenuation_alpha_per_mm"))
    mat.attenuation_alpha = parseAttenuation(*a, true);
  if (auto a = m.get("attenuation_beta_per_mm")) mat.attenuation_beta = parseAttenuation(*a, true);
  if (auto a = m.get("attenuation_gamma_per_mm"))
    mat.attenuation_gamma = parseAttenuation(*a, true);
}

Material parseMaterial(const Node& m, const std::string& name, bool is_file) {
  std::vector<std::string> keys = {"n",
                                   "n_o",
                                   "n_e",
                                   "optic_axis",
                                   "attenuation_per_mm",
                                   "attenuation_o_per_mm",
                                   "attenuation_e_per_mm",
                                   "emission",
                                   "opacity",
                                   "albedo",
                                   "phase_g",
                                   "source",
                                   "notes"};
  keys.insert(keys.end(), kBiaxialKeys.begin(), kBiaxialKeys.end());
  if (is_file) keys.insert(keys.end(), {"name", "fit", "published_2v"});
  m.allowKeys(keys);
  Material mat;
  mat.name = name;
  if (auto s = m.get("source")) mat.source = s->string();
  bool iso = m.has("n"), crystal = m.has("n_o") || m.has("n_e");
  const bool biaxial = std::any_of(kBiaxialKeys.begin(), kBiaxialKeys.end(),
                                   [&](const char* k) { return m.has(k); });
  if (iso && crystal)
    m.fail("give either \"n\" (isotropic) or \"n_o\" and \"n_e\" (uniaxial), not both");
  if (!iso && !crystal && !biaxial)
    m.fail(
        "missing \"n\" (isotropic), \"n_o\"/\"n_e\" (uniaxial) or \"n_alpha\"/\"n_beta\"/"
        "\"n_gamma\" (biaxial)");
  if (biaxial) {
    parseBiaxial(m, mat);
  } else if (iso) {
    mat.n_o = parseDispersion(m.at("n"), &mat.grin);
    mat.n_e = mat.n_o;
    if (m.has("optic_axis")) m.fail("optic_axis given for an isotropic material (use n_o and n_e)");
    if (m.has("attenuation_o_per_mm") || m.has("attenuation_e_per_mm"))
      m.fail(
          "attenuation_o_per_mm/attenuation_e_per_mm are for uniaxial materials; use "
          "attenuation_per_mm");
    if (auto a = m.get("attenuation_per_mm"))
      mat.attenuation_o = mat.attenuation_e = parseAttenuation(*a, is_file);
  } else {
    if (!m.has("n_o")) m.fail("uniaxial material is missing n_o");
    if (!m.has("n_e")) m.fail("uniaxial material is missing n_e (extraordinary index)");
    mat.uniaxial = true;
    mat.n_o = parseDispersion(m.at("n_o"), nullptr);
    mat.n_e = parseDispersion(m.at("n_e"), nullptr);
    if (auto a = m.get("optic_axis")) mat.optic_axis = a->unitVector();
    if (m.has("attenuation_per_mm"))
      m.fail("uniaxial materials take attenuation_o_per_mm and attenuation_e_per_mm");
    if (auto a = m.get("attenuation_o_per_mm")) mat.attenuation_o = parseAttenuation(*a, is_file);
    if (auto a = m.get("attenuation_e_per_mm")) mat.attenuation_e = parseAttenuation(*a, is_file);
  }
  if (auto e = m.get("emission")) mat.emission = e->color();
  if (auto o = m.get("opacity")) mat.opacity = o->number(0.0, 1.0);
  if (auto a = m.get("albedo")) {
    mat.albedo = a->color();
    if (mat.albedo.x > 1 || mat.albedo.y > 1 || mat.albedo.z > 1)
      a->fail("albedo must be in [0, 1] per band");
    // Translucent scattering is albedo·σ_t: without attenuation there is nothing to scatter.
    if (mat.opacity < 0.5 && glm::length(mat.albedo) > 0 && mat.attenuation_o.isZero() &&
        mat.attenuation_e.isZero() && mat.attenuation_alpha.isZero() &&
        mat.attenuation_beta.isZero() && mat.attenuation_gamma.isZero())
      a->fail(
          "a translucent material scatters albedo x attenuation; give attenuation_per_mm > 0 (or "
          "opacity 1 for a "
          "diffuse surface)");
  }
  if (auto g = m.get("phase_g")) {
    mat.phase_g = g->number(-1.0, 1.0);
    if (std::abs(mat.phase_g) >= 1.0)
      g->fail("phase_g must be in (-1, 1), got " + fmt(mat.phase_g));
    if (mat.opacity >= 0.5)
      g->fail(
          "phase_g is the in-scatter asymmetry of a translucent material; an opaque one is "
          "diffuse");
  }
  return mat;
}

// ------------------------------------------------------------------ objects
/// /girdle of a faceted object: {"outline": "round", "diameter"} | {"outline": "oval" | "pear" |
/// "rectangle", "length", "width"[, "corner"]}, "thickness".
GirdleOutline parseGirdle(const Node& g) {
  GirdleOutline out;
  const std::string kind = g.at("outline").string();
  if (kind == "round") {
    g.allowKeys({"outline", "diameter", "thickness"});
    out.kind = GirdleOutline::Kind::Round;
    out.length = out.width = g.at("diameter").length();
  } else if (kind == "oval" || kind == "rectangle") {
    if (kind == "oval") g.allowKeys({"outline", "length", "width", "thickness"});
    if (kind != "oval") g.allowKeys({"outline", "length", "width", "corner", "thickness"});
    out.kind = kind == "oval" ? GirdleOutline::Kind::Oval : GirdleOutline::Kind::Rectangle;
    out.length = g.at("length").length();
    out.width = g.at("width").length();
    if (auto c = g.get("corner"))
      out.corner = c->number(0.0, 0.5 * std::min(out.length, out.width));
  } else if (kind == "pear") {
    g.allowKeys({"outline", "length", "width", "thickness"});
    out.kind = GirdleOutline::Kind::Pear;
    out.length = g.at("length").length();
    out.width = g.at("width").length();
    if (!(out.width < out.length))
      g.at("width").fail(
          "a pear must be longer than wide (the point lies outside the round "
          "end), got width " +
          fmt(out.width) + " >= length " + fmt(out.length));
  } else {
    g.at("outline").fail("unknown outline '" + excerpt(kind) + "' (round, oval, rectangle, pear)");
  }
  out.thickness = g.get("thickness") ? g.at("thickness").number(0.0, kMaxCoordinateMm) : 0.0;
  return out;
}

/// Where a tier is cut to: exactly one of distance, to_center, meet.
void parsePlacement(const Node& t, FacetTier& tier) {
  const int given = int(t.has("distance")) + int(t.has("to_center")) + int(t.has("meet"));
  if (given != 1)
    t.fail("give exactly one of distance, to_center, meet (where the facets are cut to)");
  if (auto d = t.get("distance")) {
    tier.value = d->number(-kMaxCoordinateMm, kMaxCoordinateMm);
  } else if (auto c = t.get("to_center")) {
    if (tier.side != FacetSide::Crown && tier.side != FacetSide::Pavilion)
      c->fail("to_center is for crown and pavilion tiers");
    tier.place = FacetTier::Place::ToCenter;
    tier.value = c->number(-kMaxCoordinateMm, kMaxCoordinateMm);
  } else {
    const Node m = t.at("meet");
    if (m.isString()) {
      if (m.string() != "girdle")
        m.fail("expected \"girdle\", {\"tier\", \"height\"} or three [tier, index]");
      tier.place = FacetTier::Place::MeetGirdle;
    } else if (m.isObject()) {
      m.allowKeys({"tier", "height"});
      tier.place = FacetTier::Place::MeetLevel;
      tier.level_tier = m.at("tier").string();
      tier.value = m.at("height").number(-kMaxCoordinateMm, kMaxCoordinateMm);
    } else {
      if (!m.isArray() || m.size() != 3)
        m.fail("expected \"girdle\", {\"tier\", \"height\"} or three [tier, index]");
      tier.place = FacetTier::Place::MeetPoint;
      for (size_t r = 0; r < 3; ++r) {
        const Node ref = m.index(r);
        if (!ref.isArray() || ref.size() != 2) ref.fail("expected [tier name, index]");
        tier.meet[r] = {ref.index(0).string(), ref.index(1).integer(-100000, 100000)};
      }
    }
  }
}

FacetTier parseTier(const Node& t, int gear, const std::string& rel) {
  t.allowKeys({"name", "side", "angle_deg", "index", "symmetry", "first_index", "distance",
               "to_center", "meet"});
  FacetTier tier;
  tier.path = rel;
  tier.name = t.at("name").string();
  const std::string side = t.at("side").string();
  static const std::map<std::string, FacetSide> sides = {{"crown", FacetSide::Crown},
                                                         {"pavilion", FacetSide::Pavilion},
                                                         {"girdle", FacetSide::Girdle},
                                                         {"table", FacetSide::Table},
                                                         {"culet", FacetSide::Culet}};
  auto it = sides.find(side);
  if (it == sides.end())
    t.at("side").fail("unknown side '" + excerpt(side) +
                      "' (crown, pavilion, girdle, table, culet)");
  tier.side = it->second;
  const bool tilted = tier.side == FacetSide::Crown || tier.side == FacetSide::Pavilion;
  if (tilted) {
    tier.angle_deg = t.at("angle_deg").number();
    if (!(tier.angle_deg > 0 && tier.angle_deg < 90))
      t.at("angle_deg")
          .fail("must be in (0, 90) degrees from the girdle plane, got " + fmt(tier.angle_deg));
  } else if (t.has("angle_deg")) {
    t.at("angle_deg").fail("a " + side + " tier has no angle");
  }
  if (tier.side == FacetSide::Table || tier.side == FacetSide::Culet) {
    if (t.has("index") || t.has("symmetry") || t.has("first_index"))
      t.fail("a " + side + " has no index");
    tier.indices = {0};
  } else if (auto ix = t.get("index")) {
    if (t.has("symmetry") || t.has("first_index")) t.fail("give index or symmetry, not both");
    if (!ix->isArray() || ix->size() == 0) ix->fail("expected a non-empty array of gear indices");
    for (size_t k = 0; k < ix->size(); ++k) {
      const Node v = ix->index(k);
      tier.indices.push_back(v.integer(0, gear));
    }
  } else {
    const int n = t.at("symmetry").integer(1, gear);
    if (gear % n != 0)
      t.at("symmetry")
          .fail("must divide the gear's " + std::to_string(gear) + " teeth, got " +
                std::to_string(n));
    const int first = t.get("first_index") ? t.at("first_index").integer(0, gear) : gear / n;
    // As a cutter counts: from the first index on, wrapping past the gear's top tooth.
    for (int k = 0; k < n; ++k) {
      const int v = first + k * (gear / n);
      tier.indices.push_back(v > gear ? v - gear : v);
    }
  }
  parsePlacement(t, tier);
  return tier;
}

/// {"shape": "faceted", "gear", "girdle", "tiers"} or {"shape": "faceted", "file": "x.asc"}.
ConvexShape parseFaceted(const Node& o) {
  FacetedDesign design;
  if (auto f = o.get("file")) {
    if (o.has("tiers") || o.has("gear") || o.has("girdle"))
      o.fail("give either file (a GemCad .asc) or gear, girdle and tiers, not both");
    const std::filesystem::path p = namedFile(*f, "a GemCad .asc file");
    // The name must say GemCad's text export: a file of another kind is not read as one (its
    // lines would be quoted in the messages, a line of /etc/passwd say).
    std::string ext = p.extension().string();
    for (char& c : ext)
      if (c >= 'A' && c <= 'Z') c = char(c - 'A' + 'a');
    if (ext != ".asc")
      f->fail("'" + excerpt(p.filename().string()) +
              "' does not end in .asc: expected a GemCad .asc file (GemCad's text export)");
    std::string text;
    try {
      text = readTextFile(p, "a GemCad .asc file", 1u << 20);
    } catch (const std::runtime_error& e) {
      f->fail(e.what());
    }
    std::istringstream in(text);
    try {
      design = readGemCadAsc(in, shownPath(p.filename()));
    } catch (const FacetError& e) {
      f->fail(printable(e.what(), 500));
    }
  } else {
    design.gear = o.get("gear") ? o.at("gear").integer(3, 400) : 96;
    if (auto g = o.get("girdle")) design.girdle = parseGirdle(*g);
    const Node ts = o.at("tiers");
    if (!ts.isArray() || ts.size() == 0) ts.fail("expected a non-empty array of tiers");
    for (size_t k = 0; k < ts.size(); ++k)
      design.tiers.push_back(parseTier(ts.index(k), design.gear, "/tiers/" + std::to_string(k)));
  }
  try {
    return cutFaceted(design).shape;
  } catch (const FacetError& e) {
    throw SceneError(o.file() + ": " + o.path() + e.where() + ": " + printable(e.what(), 500));
  }
}

/// {"shape": "mesh", "file": "x.obj", "scale": s | [sx, sy, sz]}: a closed triangle mesh, read and
/// checked by core/scene/mesh.h. A convex one becomes its exact polyhedron (one plane per face),
/// any other an exact-distance MeshShape (sharp interfaces at its triangles, or smoothed).
ShapeGeometry parseMesh(const Node& o) {
  const Node f = o.at("file");
  const std::filesystem::path p = namedFile(f, "an .obj, .ply or .stl file");
  glm::dvec3 scale(1.0);
  const std::optional<Node> s = o.get("scale");
  if (s) {
    scale = s->isNumber() ? glm::dvec3(s->number()) : s->vec3();
    if (!(scale.x > 0 && scale.y > 0 && scale.z > 0))
      s->fail("every scale factor must be > 0, got " + fmt(std::min({scale.x, scale.y, scale.z})));
  }
  TriangleMesh mesh;
  try {
    mesh = readMesh(p);
    checkClosedMesh(mesh, excerpt(p.filename().string()));
  } catch (const std::invalid_argument& e) {
    f.fail(printable(e.what(), 800));  // room for a shortened name, its path and the reason
  } catch (const std::bad_alloc&) {
    f.fail(excerpt(p.filename().string()) + ": not enough memory to read the mesh");
  }
  // The scaled mesh, before either path: within ±kMaxCoordinateMm of the centre on each axis and
  // at least kMinVoxelMm across on each axis (a scale of 1e300 or 1e-300 made the convex path's
  // planes overflow or collapse: "the planes do not enclose a bounded solid").
  const Node& at = s ? *s : f;
  const std::string given = s && s->isNumber() ? fmt(scale.x) : point(scale);
  glm::dvec3 lo(std::numeric_limits<double>::infinity()), hi(-lo);
  for (const glm::dvec3& v : mesh.vertices) {
    lo = glm::min(lo, v * scale);
    hi = glm::max(hi, v * scale);
  }
  for (int a = 0; a < 3; ++a) {
    const double far = std::max(std::abs(lo[a]), std::abs(hi[a]));
    if (!(far <= kMaxCoordinateMm))
      at.fail("the scaled mesh must lie within ±" + fmt(kMaxCoordinateMm) +
              " mm of its centre on each axis, got a point " + fmt(far) + " mm from it along " +
              "xyz"[a] + " (scale " + given + ")");
  }
  for (int a = 0; a < 3; ++a)
    if (!(hi[a] - lo[a] >= kMinVoxelMm))
      at.fail("the scaled mesh must be at least " + fmt(kMinVoxelMm) + " mm across on each axis, " +
              "got " + fmt(hi[a] - lo[a]) + " mm along " + "xyz"[a] + " (scale " + given + ")");
  std::vector<Plane> planes;
  try {
    planes = meshFacePlanes(mesh, excerpt(p.filename().string()), kConvexMeshMaxFaces);
  } catch (const std::invalid_argument&) {
    // Not convex (or more faces than a polyhedron takes): a MeshShape.
  }
  if (planes.empty()) {
    for (glm::dvec3& v : mesh.vertices) v *= scale;
    return makeMeshShape(mesh);
  }
  return scaledConvex(planes, scale);
}

// A biaxial crystal's orientation on the object: alpha_axis and gamma_axis together, unit after
// normalising, orthogonal within 1e-6 (as on a material).
void parseObjectAxes(const Node& o, SceneObject& obj) {
  const auto a = o.get("alpha_axis"), g = o.get("gamma_axis");
  if (!a && !g) return;
  if (!a || !g) o.fail("give both alpha_axis and gamma_axis (a biaxial crystal's orientation)");
  obj.alpha_axis = a->unitVector();
  obj.gamma_axis = g->unitVector();
  const double c = glm::dot(*obj.alpha_axis, *obj.gamma_axis);
  if (std::abs(c) > 1e-6)
    g->fail("must be orthogonal to alpha_axis (|cos| <= 1e-6 after normalising both), got cos = " +
            fmt(c));
}

SceneObject parseObject(const Node& o) {
  o.requireObject();
  std::string shape = o.at("shape").string();
  glm::dvec3 center = o.get("center") ? o.at("center").position() : glm::dvec3(0.0);
  glm::dvec3 rot = o.get("rotation_deg") ? o.at("rotation_deg").vec3() : glm::dvec3(0.0);
  SceneObject obj;
  ShapeGeometry g;
  auto common = {"shape",      "center",           "rotation_deg", "material",
                 "optic_axis", "optic_axis_field", "alpha_axis",   "gamma_axis"};
  auto allow = [&](std::initializer_list<const char*> extra) {
    std::vector<const char*> keys(common);
    keys.insert(keys.end(), extra.begin(), extra.end());
    std::set<std::string> allowed(keys.begin(), keys.end());
    for (auto it = o.raw().begin(); it != o.raw().end(); ++it)
      if (!allowed.count(it.key())) {
        std::string list;
        for (const auto& k : allowed) list += (list.empty() ? "" : ", ") + k;
        o.fail("unknown key '" + excerpt(it.key()) + "' for shape '" + excerpt(shape) +
               "' (allowed: " + list + ")");
      }
  };
  try {
    if (shape == "sphere") {
      allow({"radius"});
      g = SphereShape{o.at("radius").length()};
    } else if (shape == "box") {
      allow({"size"});
      auto s = o.at("size").position();
      if (!(s.x > 0 && s.y > 0 && s.z > 0)) o.at("size").fail("all sizes must be > 0");
      g = BoxShape{s};
    } else if (shape == "rounded_box") {
      allow({"size", "radius"});
      auto s = o.at("size").position();
      if (!(s.x > 0 && s.y > 0 && s.z > 0)) o.at("size").fail("all sizes must be > 0");
      double r = o.at("radius").length();
      if (2 * r > std::min(s.x, std::min(s.y, s.z)))
        o.at("radius").fail("corner radius exceeds half the smallest side");
      g = RoundedBoxShape{s, r};
    } else if (shape == "prism") {
      allow({"apex_deg", "side", "height"});
      const Node apex = o.at("apex_deg");
      const double apex_deg = apex.number(0.0, 180.0, true, true), side = o.at("side").length();
      // The triangle's base and height at least kMinVoxelMm: 1e-300 degrees left a sliver whose
      // planes "do not enclose a bounded solid".
      const double half = 0.5 * apex_deg * std::numbers::pi / 180.0;
      const double thin = std::min(2.0 * side * std::sin(half), side * std::cos(half));
      if (!(thin >= kMinVoxelMm))
        apex.fail("the prism's cross-section would be " + fmt(thin) + " mm thin (side " +
                  fmt(side) + " mm), less than " + fmt(kMinVoxelMm) +
                  " mm: move apex_deg away from 0 and 180 or lengthen side");
      g = makePrism(apex_deg, side, o.at("height").length());
    } else if (shape == "brilliant") {
      allow({"diameter", "table", "crown_deg", "pavilion_deg", "girdle", "facets"});
      g = makeBrilliant(o.at("diameter").length(),
                        o.get("table") ? o.at("table").number(0.0, 1.0, true) : 0.57,
                        o.get("crown_deg") ? o.at("crown_deg").number() : 34.5,
                        o.get("pavilion_deg") ? o.at("pavilion_deg").number() : 40.75,
                        o.get("girdle") ? o.at("girdle").number(0.0, 0.5) : 0.02,
                        o.get("facets") ? o.at("facets").integer(3, 64) : 16);
    } else if (shape == "faceted") {
      allow({"gear", "girdle", "tiers", "file"});
      g = parseFaceted(o);
    } else if (shape == "planes") {
      allow({"planes"});
      auto p = o.at("planes");
      if (!p.isArray()) p.fail("expected an array of [nx, ny, nz, d]");
      // Validation is O(n²) (finishConvex): 4096 planes take ~1.5 s, and nothing may hang.
      if (p.size() > kMaxPlanes)
        p.fail("at most " + std::to_string(kMaxPlanes) + " planes, got " +
               std::to_string(p.size()));
      ConvexShape c;
      for (size_t i = 0; i < p.size(); ++i) {
        auto v = p.index(i).numbers();
        if (v.size() != 4) p.index(i).fail("expected [nx, ny, nz, d]");
        glm::dvec3 n(v[0], v[1], v[2]);
        double len = glm::length(n);
        if (!(len > 1e-12)) p.index(i).fail("plane normal must be non-zero");
        if (!(std::abs(v[3] / len) <= kMaxCoordinateMm))
          p.index(i).fail("the plane's distance d/|n| from the centre must be within ±" +
                          fmt(kMaxCoordinateMm) + " mm, got " + fmt(v[3] / len));
        c.planes.push_back({n / len, v[3] / len});
      }
      finishConvex(c);
      g = c;
    } else if (shape == "mesh") {
      allow({"file", "scale"});
      g = parseMesh(o);
    } else {
      o.at("shape").fail(
          "unknown shape '" + excerpt(shape) +
          "' (sphere, box, rounded_box, prism, brilliant, faceted, planes, mesh, polarizer)");
    }
  } catch (const std::invalid_argument& e) {
    o.fail(e.what());
  }
  obj.shape = Shape(shape, g, center, rot);
  obj.material = o.at("material").string();
  if (auto a = o.get("optic_axis")) obj.optic_axis = a->unitVector();
  if (auto f = o.get("optic_axis_field")) {
    std::string kind = f->string();
    if (kind == "radial")
      obj.radial_axis = true;
    else if (kind != "uniform")
      f->fail("unknown optic_axis_field '" + excerpt(kind) + "' (uniform, radial)");
    if (obj.radial_axis && obj.optic_axis)
      f->fail("give either optic_axis or optic_axis_field \"radial\", not both");
  }
  parseObjectAxes(o, obj);
  return obj;
}

/// Parse JSON text, refusing a key that appears twice in one object (nlohmann keeps the last
/// one silently): the parser callback sees every key event, and a stack of the open containers
/// gives the JSON path of the duplicate. Syntax errors, numbers that overflow a double (1e999)
/// and NUL bytes (where nlohmann's parser stops reading, ignoring the rest) are SceneErrors naming
/// the file.
json parseJson(const std::string& text, const std::string& file) {
  if (const std::string nul = nulByteProblem(text, file, "JSON text"); !nul.empty())
    throw SceneError(nul);
  struct Open {
    bool array;
    std::set<std::string> keys;
    std::string key;  // object: the current key
    long index = -1;  // array: the current element
  };
  std::vector<Open> open;
  auto path = [&] {
    std::string p;
    for (const Open& f : open) p += "/" + (f.array ? std::to_string(f.index) : excerpt(f.key));
    return p;
  };
  auto element = [&] {
    if (!open.empty() && open.back().array) ++open.back().index;
  };
  json::parser_callback_t cb = [&](int, json::parse_event_t ev, json& parsed) {
    switch (ev) {
      case json::parse_event_t::object_start:
        element();
        open.push_back({false, {}, {}, -1});
        break;
      case json::parse_event_t::array_start:
        element();
        open.push_back({true, {}, {}, -1});
        break;
      case json::parse_event_t::object_end:
      case json::parse_event_t::array_end:
        open.pop_back();
        break;
      case json::parse_event_t::value:
        element();
        break;
      case json::parse_event_t::key: {
        Open& f = open.back();
        f.key = parsed.get<std::string>();
        if (!f.keys.insert(f.key).second)
          throw SceneError(file + ": " + path() + ": duplicate key '" + excerpt(f.key) +
                           "' (each key may appear once per object; which value was meant?)");
        break;
      }
    }
    return true;
  };
  try {
    return json::parse(text, cb);
  } catch (const json::exception& e) {  // parse errors and number overflow (1e999)
    throw SceneError(file + ": malformed JSON: " + printable(e.what(), 300));
  }
}

/// The text of a scene or material file (core/io/text_file.h: a regular file of at most 64 MiB,
/// no NUL byte); every refusal a SceneError "FILE: why".
std::string readSceneText(const std::filesystem::path& path, const std::string& what) {
  try {
    return readTextFile(path, what);
  } catch (const std::runtime_error& e) {
    throw SceneError(e.what());
  }
}

json readJsonFile(const std::filesystem::path& path, const char* what) {
  return parseJson(readSceneText(path, std::string("a ") + what), path.string());
}

}  // namespace

// ------------------------------------------------------------------ small physics helpers
double GrinProfile::index(const glm::dvec3& x) const {
  switch (type) {
    case Type::None:
      return n0;
    case Type::Linear:
      return n0 + glm::dot(gradient, x - origin);
    case Type::Luneburg: {
      double r2 = glm::dot(x - origin, x - origin) / (radius * radius);
      return std::sqrt(std::max(2.0 - r2, 1.0));
    }
    case Type::MaxwellFisheye: {
      double r2 = glm::dot(x - origin, x - origin) / (radius * radius);
      return std::max(n0 / (1.0 + r2), 1.0);
    }
  }
  return n0;
}

glm::dvec3 GrinProfile::indexGradient(const glm::dvec3& x) const {
  switch (type) {
    case Type::None:
      return glm::dvec3(0.0);
    case Type::Linear:
      return gradient;
    case Type::Luneburg: {
      double r2 = glm::dot(x - origin, x - origin) / (radius * radius);
      if (2.0 - r2 <= 1.0) return glm::dvec3(0.0);
      return -(x - origin) / (radius * radius * std::sqrt(2.0 - r2));
    }
    case Type::MaxwellFisheye: {
      double r2 = glm::dot(x - origin, x - origin) / (radius * radius);
      if (n0 / (1.0 + r2) <= 1.0) return glm::dvec3(0.0);
      return -2.0 * n0 * (x - origin) / (radius * radius * (1.0 + r2) * (1.0 + r2));
    }
  }
  return glm::dvec3(0.0);
}

double Light::spectralPower(double lambda_nm) const {
  if (spectrum_nm.empty()) return spectrum::d65(lambda_nm);
  if (lambda_nm < spectrum_nm.front() || lambda_nm > spectrum_nm.back()) return 0.0;
  size_t k = size_t(std::upper_bound(spectrum_nm.begin(), spectrum_nm.end(), lambda_nm) -
                    spectrum_nm.begin());
  if (k >= spectrum_nm.size()) return spectrum_power.back();
  double t = (lambda_nm - spectrum_nm[k - 1]) / (spectrum_nm[k] - spectrum_nm[k - 1]);
  return spectrum_power[k - 1] + t * (spectrum_power[k] - spectrum_power[k - 1]);
}

double Attenuation::at(double lambda_nm) const {
  if (!wavelengths_nm.empty()) {
    if (lambda_nm <= wavelengths_nm.front()) return values.front();
    if (lambda_nm >= wavelengths_nm.back()) return values.back();
    auto it = std::upper_bound(wavelengths_nm.begin(), wavelengths_nm.end(), lambda_nm);
    size_t i = size_t(it - wavelengths_nm.begin());
    double t = (lambda_nm - wavelengths_nm[i - 1]) / (wavelengths_nm[i] - wavelengths_nm[i - 1]);
    return values[i - 1] + t * (values[i] - values[i - 1]);
  }
  // RGB bands at 612 (r), 549 (g), 465 (b) nm.
  if (lambda_nm <= 465.0) return rgb.b;
  if (lambda_nm >= 612.0) return rgb.r;
  if (lambda_nm <= 549.0) return rgb.b + (rgb.g - rgb.b) * (lambda_nm - 465.0) / (549.0 - 465.0);
  return rgb.g + (rgb.r - rgb.g) * (lambda_nm - 549.0) / (612.0 - 549.0);
}

bool Attenuation::isZero() const {
  if (!values.empty())
    return std::all_of(values.begin(), values.end(), [](double v) { return v == 0.0; });
  return rgb == glm::dvec3(0.0);
}

glm::dvec3 Environment::lookup(const glm::dvec3& d) const {
  // Latitude-longitude parameterisation: y is up; u = atan2(x, -z)/(2π) + 0.5, v = acos(y)/π.
  double u = std::atan2(d.x, -d.z) / (2.0 * std::numbers::pi) + 0.5;
  double v = std::acos(std::clamp(d.y, -1.0, 1.0)) / std::numbers::pi;
  switch (type) {
    case Type::Constant:
      return radiance * intensity;
    case Type::Checker: {
      long iu = long(std::floor(u * 2.0 * squares)), iv = long(std::floor(v * squares));
      return ((iu + iv) & 1 ? color_b : color_a) * intensity;
    }
    case Type::LatLong: {
      // Bilinear, wrapping in u, clamped in v; texel centres at (i + 0.5)/w.
      double fx = u * image_width - 0.5, fy = v * image_height - 0.5;
      long x0 = long(std::floor(fx)), y0 = long(std::floor(fy));
      double tx = fx - double(x0), ty = fy - double(y0);
      auto texel = [&](long x, long y) {
        x = ((x % image_width) + image_width) % image_width;
        y = std::clamp<long>(y, 0, image_height - 1);
        const float* p = &image_rgba[size_t(4 * (y * image_width + x))];
        return glm::dvec3(p[0], p[1], p[2]);
      };
      glm::dvec3 c = (1 - ty) * ((1 - tx) * texel(x0, y0) + tx * texel(x0 + 1, y0)) +
                     ty * ((1 - tx) * texel(x0, y0 + 1) + tx * texel(x0 + 1, y0 + 1));
      return c * intensity;
    }
  }
  return glm::dvec3(0.0);
}

bool Scene::anyUniaxial() const {
  return std::any_of(materials.begin(), materials.end(),
                     [](const auto& m) { return m.second.uniaxial; });
}

bool Scene::anyBiaxial() const {
  return std::any_of(materials.begin(), materials.end(),
                     [](const auto& m) { return m.second.biaxial; });
}

bool Scene::anyScattering() const {
  // As the voxeliser sets VolumeSet::scattering: an albedo that is non-zero as a float.
  return std::any_of(materials.begin(), materials.end(), [](const auto& m) {
    const glm::dvec3& a = m.second.albedo;
    return float(a.x) != 0.0f || float(a.y) != 0.0f || float(a.z) != 0.0f;
  });
}

bool Scene::anyDispersive() const {
  return std::any_of(materials.begin(), materials.end(), [](const auto& m) {
    return !m.second.n_o.isDispersionless() || !m.second.n_e.isDispersionless();
  });
}

std::vector<std::filesystem::path> materialSearchPath() {
  std::vector<std::filesystem::path> dirs;
  if (const char* env = std::getenv("EIKON_MATERIALS_PATH")) {
    std::stringstream ss(env);
    std::string item;
    while (std::getline(ss, item, ':'))
      if (!item.empty()) dirs.emplace_back(item);
  }
  dirs.emplace_back(EIKON_MATERIALS_DIR);
  return dirs;
}

Material loadMaterialFile(const std::filesystem::path& path) {
  json j = readJsonFile(path, "material file");
  const std::string file = path.string();
  Node root(j, "", file);
  std::string name = root.get("name") ? root.at("name").string() : path.stem().string();
  return parseMaterial(root, name, true);
}

// ------------------------------------------------------------------ polarisation
/// "polarization": "unpolarized" or {"stokes": [S0, S1, S2, S3], "reference": [x, y, z]}.
static Polarization parsePolarization(const Node& p) {
  Polarization pol;
  if (p.isString()) {
    const std::string v = p.string();
    if (v != "unpolarized")
      p.fail("unknown polarization '" + excerpt(v) +
             "' (\"unpolarized\" or {\"stokes\": [S0, S1, S2, S3], \"reference\": [x, y, z]})");
    return pol;
  }
  p.allowKeys({"stokes", "reference"});
  const Node s = p.at("stokes");
  const std::vector<double> v = s.numbers();
  if (v.size() != 4)
    s.fail("expected [S0, S1, S2, S3], got " + std::to_string(v.size()) + " numbers");
  if (!(v[0] > 0)) s.index(0).fail("S0 must be > 0, got " + fmt(v[0]));
  const double dop = std::sqrt(v[1] * v[1] + v[2] * v[2] + v[3] * v[3]) / v[0];
  if (dop > 1.0 + 1e-9)
    s.fail("the degree of polarisation sqrt(S1² + S2² + S3²)/S0 must be <= 1, got " + fmt(dop));
  pol.stokes = glm::dvec4(1.0, v[1] / v[0], v[2] / v[0], v[3] / v[0]);
  if (auto r = p.get("reference")) pol.reference = r->unitVector();
  return pol;
}

/// {"shape": "polarizer", "center", "normal", "transmission_axis", "size": [w, h]}.
static PolarizerSheet parsePolarizer(const Node& o) {
  o.allowKeys({"shape", "center", "normal", "transmission_axis", "size"});
  PolarizerSheet sheet;
  sheet.center = o.at("center").position();
  const Node n = o.at("normal");
  const glm::dvec3 nv = n.vec3();
  const double len = glm::length(nv);
  if (!(len > 1e-12)) n.fail("must be a non-zero unit vector, got (0, 0, 0)");
  if (std::abs(len - 1.0) > 1e-6) n.fail("must be a unit vector, got length " + fmt(len));
  sheet.normal = nv / len;
  const Node a = o.at("transmission_axis");
  const glm::dvec3 av = a.unitVector();
  if (std::abs(glm::dot(av, sheet.normal)) > 1e-6)
    a.fail("must be perpendicular to the normal (it lies in the sheet), got a cosine of " +
           fmt(glm::dot(av, sheet.normal)) + " with it");
  sheet.axis = glm::normalize(av - glm::dot(av, sheet.normal) * sheet.normal);
  const Node sz = o.at("size");
  if (!sz.isArray() || sz.size() != 2) sz.fail("expected [width, height] in mm");
  sheet.width = sz.index(0).length();
  sheet.height = sz.index(1).length();
  return sheet;
}

// ------------------------------------------------------------------ lights
static Light parseLight(const Node& l) {
  Light light;
  std::string type = l.at("type").string();
  if (type == "directional") {
    l.allowKeys({"type", "direction", "irradiance", "beam_radius", "beam_center", "spectrum",
                 "polarization"});
    light.type = Light::Type::Directional;
    light.direction = l.at("direction").unitVector();
    if (auto v = l.get("irradiance")) light.irradiance = v->number(0.0, 1e12);
    if (auto r = l.get("beam_radius")) light.beam_radius = r->length();
    if (auto c = l.get("beam_center")) {
      if (!l.has("beam_radius")) c->fail("beam_center needs beam_radius (the beam's radius in mm)");
      light.position = c->position();
    }
  } else if (type == "point" || type == "spot") {
    if (type == "point")
      l.allowKeys({"type", "position", "intensity", "spectrum", "polarization"});
    else
      l.allowKeys({"type", "position", "direction", "cone_half_angle_deg", "intensity", "spectrum",
                   "polarization"});
    light.type = type == "point" ? Light::Type::Point : Light::Type::Spot;
    light.position = l.at("position").position();
    if (auto v = l.get("intensity")) light.irradiance = v->number(0.0, 1e12);
    if (type == "spot") {
      light.direction = l.at("direction").unitVector();
      light.cone_half_angle_deg = l.at("cone_half_angle_deg").number(0.0, 90.0, true);
    }
  } else {
    l.at("type").fail("unknown light type '" + excerpt(type) + "' (directional, point, spot)");
  }
  if (auto p = l.get("polarization")) light.polarization = parsePolarization(*p);
  if (auto sp = l.get("spectrum")) {
    if (sp->isString()) {
      std::string name = sp->string();
      if (name == "E") {
        light.spectrum_nm = {380.0, 780.0};
        light.spectrum_power = {1.0, 1.0};
      } else if (name != "D65") {
        sp->fail("unknown spectrum '" + excerpt(name) +
                 "' (\"D65\", \"E\" or {\"wavelength_nm\": [...], \"power\": [...]})");
      }
    } else {
      sp->allowKeys({"wavelength_nm", "power"});
      light.spectrum_nm = sp->at("wavelength_nm").numbers();
      light.spectrum_power = sp->at("power").numbers();
      if (light.spectrum_nm.size() != light.spectrum_power.size() || light.spectrum_nm.size() < 2)
        sp->fail("wavelength_nm and power must have the same length, at least 2");
      double total = 0;
      for (size_t k = 0; k < light.spectrum_nm.size(); ++k) {
        if (!(light.spectrum_nm[k] > 0))
          sp->at("wavelength_nm")
              .index(k)
              .fail("wavelengths must be > 0 nm, got " + fmt(light.spectrum_nm[k]));
        if (light.spectrum_power[k] < 0) sp->at("power").index(k).fail("must be >= 0");
        // A relative spectrum: its scale is the light's irradiance or intensity. Bounded so that
        // its integral cannot overflow (1e308 twice read as "no power").
        if (light.spectrum_power[k] > kMaxColor)
          sp->at("power").index(k).fail(std::string("must be at most ") + kMaxColorText +
                                        " (a relative spectrum), got " +
                                        fmt(light.spectrum_power[k]));
        if (k && !(light.spectrum_nm[k] > light.spectrum_nm[k - 1]))
          sp->at("wavelength_nm").index(k).fail("wavelength_nm must be strictly increasing");
        total += light.spectrum_power[k];
      }
      if (light.spectrum_nm.front() >= 780.0 || light.spectrum_nm.back() <= 380.0 || !(total > 0))
        sp->fail("the spectrum has no power in 380-780 nm");
    }
  }
  return light;
}

// parseScene's stages, one per top-level key of the scene (and the checks of each object against
// the volume); each fails with the JSON path of what it reads.
static void parseCamera(const Node& c, Camera& cam) {
  c.allowKeys({"position", "look_at", "up", "fov_deg", "width", "height", "analyzer"});
  if (auto v = c.get("position")) cam.position = v->position();
  if (auto v = c.get("look_at")) cam.look_at = v->position();
  if (auto v = c.get("up")) cam.up = v->unitVector();
  if (auto v = c.get("fov_deg")) cam.fov_deg = v->number(0.0, 179.0, true);
  if (auto v = c.get("width")) cam.width = v->integer(1, 16384);
  if (auto v = c.get("height")) cam.height = v->integer(1, 16384);
  glm::dvec3 fwd = cam.look_at - cam.position;
  if (glm::length(fwd) < 1e-9) c.fail("position and look_at coincide");
  if (glm::length(glm::cross(glm::normalize(fwd), cam.up)) < 1e-6)
    c.fail("up is parallel to the viewing direction");
  if (auto a = c.get("analyzer")) {
    cam.analyzer = a->unitVector();
    if (glm::length(glm::cross(glm::normalize(fwd), *cam.analyzer)) < 1e-6)
      a->fail(
          "the analyzer's transmission axis is parallel to the viewing direction; it must have "
          "a component in the image plane");
  }
}

/// An environment map's pixels are radiances: each channel must be >= 0 and at most kMaxColor
/// after the environment's intensity (the reader has refused NaN and Inf).
static void checkEnvironmentPixels(const Node& file, const Environment& env) {
  const double most = kMaxColor / std::max(env.intensity, 1e-300);
  for (size_t i = 0; i < env.image_rgba.size() / 4; ++i)
    for (size_t k = 0; k < 3; ++k) {
      const double v = env.image_rgba[4 * i + k];
      if (v >= 0 && v <= most) continue;
      const std::string where = "'" + env.image_path.string() + "': pixel (" +
                                std::to_string(i % size_t(env.image_width)) + ", " +
                                std::to_string(i / size_t(env.image_width)) + ") channel " +
                                "RGB"[k] + " is " + fmt(v);
      if (v < 0) file.fail(where + "; environment radiance must be >= 0");
      if (v * env.intensity > kMaxColor)
        file.fail(where + ": times the intensity " + fmt(env.intensity) +
                  ", above the largest environment radiance " + kMaxColorText);
    }
}

static void parseEnvironment(const Node& e, Environment& env) {
  std::string type = e.at("type").string();
  if (auto v = e.get("intensity")) env.intensity = v->number(0.0, 1e9);
  // A colour times the intensity is the radiance a ray sees: at most kMaxColor.
  auto radiance = [&](const Node& c) {
    const glm::dvec3 v = c.color();
    for (int k = 0; k < 3; ++k)
      if (v[k] * env.intensity > kMaxColor)
        (c.isNumber() ? c : c.index(size_t(k)))
            .fail(fmt(v[k]) + " times the intensity " + fmt(env.intensity) +
                  " is above the largest environment radiance " + kMaxColorText);
    return v;
  };
  if (type == "checker") {
    e.allowKeys({"type", "squares", "color_a", "color_b", "intensity", "polarization"});
    env.type = Environment::Type::Checker;
    if (auto v = e.get("squares")) env.squares = v->integer(1, 4096);
    if (auto v = e.get("color_a")) env.color_a = radiance(*v);
    if (auto v = e.get("color_b")) env.color_b = radiance(*v);
  } else if (type == "constant") {
    e.allowKeys({"type", "radiance", "intensity", "polarization"});
    env.type = Environment::Type::Constant;
    if (auto v = e.get("radiance")) env.radiance = radiance(*v);
  } else if (type == "latlong") {
    e.allowKeys({"type", "file", "intensity", "polarization"});
    env.type = Environment::Type::LatLong;
    const std::filesystem::path p = namedFile(e.at("file"), "an EXR image");
    env.image_path = p;
    std::error_code ec;
    const auto file_type = std::filesystem::status(p, ec).type();
    if (ec && file_type != std::filesystem::file_type::not_found)
      e.at("file").fail(shownPath(p) + ": cannot open an EXR image: " + errorReason(ec));
    if (file_type == std::filesystem::file_type::directory)
      e.at("file").fail(shownPath(p) + ": is a directory, expected an EXR image");
    try {
      auto img = readExrRgba(p, 16384, 8192);
      env.image_width = img.width;
      env.image_height = img.height;
      env.image_rgba = std::move(img.rgba);
    } catch (const std::exception& ex) {
      e.at("file").fail(ex.what());
    }
    checkEnvironmentPixels(e.at("file"), env);
  } else {
    e.at("type").fail("unknown environment type '" + excerpt(type) +
                      "' (checker, constant, latlong)");
  }
  if (auto p = e.get("polarization")) env.polarization = parsePolarization(*p);
}

// "environment": {"preset": NAME, ...}: the gem studio's lighting (core/scene/gem_lighting.h)
// about the scene camera's viewing direction, made into a latlong image here.
static void parseGemEnvironment(const Node& e, const Camera& camera, Environment& env) {
  e.allowKeys({"preset", "head_shadow_deg", "spot_radius_deg", "spot_radiance", "width"});
  GemLighting g;
  if (!parseGemPreset(e.at("preset").string(), g.preset))
    e.at("preset").fail("unknown preset '" + excerpt(e.at("preset").string()) + "' (" +
                        gemPresetNames() + ")");
  if (auto v = e.get("head_shadow_deg")) g.head_shadow_deg = v->number(0.0, 89.0);
  if (auto v = e.get("spot_radius_deg")) g.spot_radius_deg = v->number(0.1, 20.0);
  if (auto v = e.get("spot_radiance")) g.spot_radiance = v->number(0.0, kMaxColor, true);
  if (auto v = e.get("width")) g.width = int(v->integer(64, 8192));
  makeGemEnvironment(g, camera, env);
}

static void parseVolume(const Node& v, VolumeSpec& vol) {
  v.allowKeys({"bounds_min", "bounds_max", "resolution", "smoothing_voxels", "smoothing_method"});
  if (auto b = v.get("bounds_min")) vol.bounds_min = b->position();
  if (auto b = v.get("bounds_max")) vol.bounds_max = b->position();
  glm::dvec3 ext = vol.bounds_max - vol.bounds_min;
  if (!(ext.x > 0 && ext.y > 0 && ext.z > 0))
    v.fail("bounds_max must exceed bounds_min on every axis");
  if (auto r = v.get("resolution"))
    vol.resolution = r->integer(4, 1 << 20);  // device limit checked at upload
  const double h = std::max(ext.x, std::max(ext.y, ext.z)) / vol.resolution;
  if (!(h >= kMinVoxelMm))
    (v.has("resolution") ? v.at("resolution") : v)
        .fail("the voxel edge (longest side / resolution) is " + fmt(h) +
              " mm, below the smallest " + fmt(kMinVoxelMm) +
              " mm; enlarge the bounds or lower the resolution");
  const bool min_farther = glm::length(vol.bounds_min) > glm::length(vol.bounds_max);
  const char* far_key = min_farther ? "bounds_min" : "bounds_max";
  const double offset = glm::length(min_farther ? vol.bounds_min : vol.bounds_max) / h;
  if (!(offset <= kMaxOffsetVoxels))
    (v.has(far_key) ? v.at(far_key) : v)
        .fail("the volume reaches " + fmt(offset) + " voxels (of " + fmt(h) +
              " mm) from the origin; the GPU's " +
              "single-precision positions resolve the grid only within " + fmt(kMaxOffsetVoxels) +
              " voxels of it (move the scene towards the origin or lower the resolution)");
  if (auto s = v.get("smoothing_voxels")) vol.smoothing_voxels = s->number(0.0, 8.0);
  if (auto s = v.get("smoothing_method")) {
    std::string m = s->string();
    if (m == "analytic")
      vol.smoothing = VolumeSpec::Smoothing::Analytic;
    else if (m == "gaussian")
      vol.smoothing = VolumeSpec::Smoothing::Gaussian;
    else
      s->fail("unknown smoothing_method '" + excerpt(m) + "' (analytic, gaussian)");
  }
}

/// An object's material not defined under /materials comes from the material library.
static void loadLibraryMaterial(const Node& o, const SceneObject& obj, Scene& scene) {
  // A library name is a file name inside a library directory, never a path: "../x" or
  // "/abs/x" would read any JSON file on the machine.
  const std::string& name = obj.material;
  if (name.empty() || name == "." || name == ".." ||
      name.find_first_of(std::string("/\\\0", 3)) != std::string::npos)
    o.at("material")
        .fail("material name '" + excerpt(name) +
              "' is not a plain name (no '/', '\\' or NUL, not '.' or " +
              "'..'): library materials are looked up inside the material library only; define " +
              "others under /materials");
  std::optional<std::filesystem::path> file;
  try {
    file = findLibraryMaterial(name);
  } catch (const std::filesystem::filesystem_error& e) {  // a name the system cannot look up
    o.at("material")
        .fail("cannot look up the library material '" + excerpt(name) + "' as " +
              shownPath(e.path1()) + ": " + errorReason(e.code()));
  }
  if (file) {
    scene.materials[obj.material] = loadMaterialFile(*file);
    return;
  }
  std::vector<std::string> defined;
  for (const auto& m : scene.materials) defined.push_back(m.first);
  o.at("material")
      .fail("unknown material '" + excerpt(obj.material) +
            "': not defined under /materials and not in the material library; " +
            unknownMaterialHint(name, defined));
}

namespace {
/// Warnings of one kind after the first kMaxWarningsOfAKind are counted, not kept: a scene of
/// 70 000 small objects near the volume's faces printed 22 000 lines before its error.
constexpr size_t kMaxWarningsOfAKind = 10;
class WarningsOfAKind {
 public:
  /// `kind` says what the warnings are about, for the line that counts those left out.
  WarningsOfAKind(std::vector<std::string>& out, std::string file, std::string kind)
      : out_(out), file_(std::move(file)), kind_(std::move(kind)) {}
  void add(const std::string& text) {
    if (++count_ <= kMaxWarningsOfAKind) out_.push_back(printable(text));
  }
  /// The line counting the warnings left out, if any.
  void finish() {
    if (count_ > kMaxWarningsOfAKind)
      out_.push_back(printable(file_ + ": ... and " + std::to_string(count_ - kMaxWarningsOfAKind) +
                               " more such warnings (" + kind_ + ")"));
  }

 private:
  std::vector<std::string>& out_;
  std::string file_, kind_;
  size_t count_ = 0;
};
}  // namespace

/// An object wholly outside the volume would vanish from the render, and one that covers it
/// would fill it with no surface inside: neither may happen silently. The shape lies within its
/// bounding sphere (exact for spheres), and every shape is convex, so it covers the box if it
/// holds the box's 8 corners. Returns whether it covers the volume (then warned about).
static bool checkObjectInVolume(const Node& o, const SceneObject& obj, const Scene& scene,
                                const std::string& file, WarningsOfAKind& warnings) {
  const auto& vol = scene.volume;
  auto [lo, hi] = obj.shape.bounds();
  const double r = 0.5 * (hi.x - lo.x);
  const glm::dvec3 c = obj.shape.center();
  if (glm::length(c - glm::clamp(c, vol.bounds_min, vol.bounds_max)) > r)
    o.fail("the object lies entirely outside the volume " + box(vol) +
           ", so nothing of it would be rendered; move it inside or enlarge the volume");
  bool covers = true;
  for (int corner = 0; corner < 8 && covers; ++corner)
    covers = obj.shape.contains(glm::dvec3(corner & 1 ? vol.bounds_max.x : vol.bounds_min.x,
                                           corner & 2 ? vol.bounds_max.y : vol.bounds_min.y,
                                           corner & 4 ? vol.bounds_max.z : vol.bounds_min.z));
  if (covers)
    warnings.add(file + ": " + o.path() + ": the object covers the whole volume " + box(vol) +
                 ": it fills the volume and none of its surface is inside, so it bends no ray " +
                 "(shrink it or enlarge the volume)");
  return covers;
}

/// A gradient-index profile must give n in [1, 10] wherever the object is inside the volume
/// (sampled on a 17³ lattice of the overlap of its box with the volume).
static void checkGrinIndex(const Node& o, const SceneObject& obj, const Material& mat,
                           const VolumeSpec& vol) {
  auto [lo, hi] = obj.shape.bounds();
  lo = glm::max(lo, vol.bounds_min);
  hi = glm::min(hi, vol.bounds_max);
  for (int k = 0; k <= 16; ++k)
    for (int jj = 0; jj <= 16; ++jj)
      for (int ii = 0; ii <= 16; ++ii) {
        glm::dvec3 p = lo + (hi - lo) * glm::dvec3(ii, jj, k) / 16.0;
        if (!obj.shape.contains(p)) continue;
        double n = mat.grin.type == GrinProfile::Type::Linear
                       ? mat.grin.n0 + glm::dot(mat.grin.gradient, p - mat.grin.origin)
                       : mat.grin.index(p);
        if (mat.grin.type == GrinProfile::Type::Luneburg) {
          double r2 = glm::dot(p - mat.grin.origin, p - mat.grin.origin) /
                      (mat.grin.radius * mat.grin.radius);
          n = r2 <= 2.0 ? std::sqrt(2.0 - r2) : std::nan("");
        }
        if (!(n >= kMinIndex && n <= kMaxIndex))
          o.at("material")
              .fail("gradient-index material '" + excerpt(obj.material) + "' gives n = " + fmt(n) +
                    (n > kMaxIndex   ? ", above 10"
                     : std::isnan(n) ? ", undefined"
                                     : ", below 1") +
                    ", inside this object at (" + fmt(p.x) + ", " + fmt(p.y) + ", " + fmt(p.z) +
                    ") (indices must be in [1, 10])");
      }
}

/// A biaxial crystal renders with sharp interfaces and its own principal axes only; an object of
/// another material takes no alpha_axis/gamma_axis.
static void checkBiaxialObject(const Node& o, const SceneObject& obj, const Material& mat,
                               const Scene& scene) {
  if (!mat.biaxial) {
    if (obj.alpha_axis)
      o.at("alpha_axis").fail("alpha_axis given for a material that is not biaxial");
    return;
  }
  const std::string what = "biaxial material '" + excerpt(obj.material) + "'";
  if (scene.interfaces != Scene::Interfaces::Sharp)
    o.at("material")
        .fail(what +
              ": \"interfaces\": \"smoothed\" is not yet for biaxial crystals "
              "(use the default, \"sharp\")");
  if (obj.optic_axis)
    o.at("optic_axis")
        .fail("optic_axis given for a " + what + " (orient it with alpha_axis and gamma_axis)");
  if (obj.radial_axis)
    o.at("optic_axis_field")
        .fail("optic-axis fields are not yet for biaxial crystals (" + what + ")");
}

/// /objects: each object, its material (from the library if not defined in the scene) and its
/// checks against the volume; polariser sheets go to scene.polarizers. Returns the objects (index
/// in scene.objects) that cover the whole volume; json_index[k] is object k's index in /objects.
static std::set<size_t> parseObjects(const Node& objs, Scene& scene, const std::string& file,
                                     std::vector<size_t>& json_index) {
  if (!objs.isArray()) objs.fail("expected an array of objects");
  // The count first, before any object's warnings (70 000 objects printed 22 000 of them first).
  if (scene.interfaces == Scene::Interfaces::Sharp && objs.size() > kMaxSharpObjects) {
    size_t count = 0;
    for (const json& o : objs.raw())
      count += !(o.is_object() && o.contains("shape") && o.at("shape") == "polarizer");
    if (count > kMaxSharpObjects)
      objs.fail("sharp interfaces allow at most " + std::to_string(kMaxSharpObjects) +
                " objects, got " + std::to_string(count) +
                " (or set \"interfaces\": \"smoothed\")");
  }
  std::set<size_t> covering;  // objects that cover the whole volume (warned about once)
  WarningsOfAKind warnings(scene.warnings, file, "objects that cover the whole volume");
  for (size_t i = 0; i < objs.size(); ++i) {
    Node o = objs.index(i);
    o.requireObject();
    if (o.has("shape") && o.at("shape").isString() && o.at("shape").string() == "polarizer") {
      scene.polarizers.push_back(parsePolarizer(o));
      scene.polarizers.back().object_index = i;
      continue;
    }
    SceneObject obj = parseObject(o);
    if (!scene.materials.count(obj.material)) loadLibraryMaterial(o, obj, scene);
    const Material& mat = scene.materials[obj.material];
    checkBiaxialObject(o, obj, mat, scene);
    if (obj.radial_axis && !mat.uniaxial)
      o.at("optic_axis_field").fail("optic_axis_field given for an isotropic material");
    if (mat.uniaxial && !obj.optic_axis && !mat.optic_axis && !obj.radial_axis)
      o.fail("uniaxial material '" + excerpt(obj.material) +
             "' needs an optic_axis (on the object or the material)");
    if (!mat.uniaxial && obj.optic_axis)
      o.at("optic_axis").fail("optic_axis given for an isotropic material");
    if (checkObjectInVolume(o, obj, scene, file, warnings)) covering.insert(scene.objects.size());
    if (mat.grin.type != GrinProfile::Type::None) checkGrinIndex(o, obj, mat, scene.volume);
    scene.objects.push_back(std::move(obj));
    json_index.push_back(i);
  }
  warnings.finish();
  return covering;
}

/// The volume's faces must lie in the ambient medium (rays leave straight from there): warn if an
/// object comes within the smoothing reach (3σ + 1 voxel) of a face, sampled on each face.
static void warnObjectsNearFaces(Scene& scene, const std::set<size_t>& covering,
                                 const std::vector<size_t>& json_index, const std::string& file) {
  const auto& v = scene.volume;
  glm::dvec3 ext = v.bounds_max - v.bounds_min;
  double h = std::max(ext.x, std::max(ext.y, ext.z)) / v.resolution;
  double margin = (3.0 * v.smoothing_voxels + 1.0) * h;
  WarningsOfAKind warnings(scene.warnings, file, "objects near the volume's boundary");
  for (size_t i = 0; i < scene.objects.size(); ++i) {
    // An object with the ambient index everywhere (a haze, an opaque floor) refracts nothing.
    const Material& mat = scene.materials[scene.objects[i].material];
    bool refracts = mat.uniaxial || mat.biaxial || mat.grin.type != GrinProfile::Type::None;
    for (double l = 380.0; l <= 780.0 && !refracts; l += 40.0)
      refracts = std::abs(mat.n_o.index(l) - scene.ambient_index) > 1e-12;
    if (!refracts || covering.count(i)) continue;
    double closest = 1e300;
    for (int axis = 0; axis < 3; ++axis)
      for (int side = 0; side < 2; ++side)
        for (int a = 0; a <= 24; ++a)
          for (int b = 0; b <= 24; ++b) {
            glm::dvec3 q;
            q[axis] = side ? v.bounds_max[axis] : v.bounds_min[axis];
            q[(axis + 1) % 3] = v.bounds_min[(axis + 1) % 3] + ext[(axis + 1) % 3] * a / 24.0;
            q[(axis + 2) % 3] = v.bounds_min[(axis + 2) % 3] + ext[(axis + 2) % 3] * b / 24.0;
            closest = std::min(closest, scene.objects[i].shape.signedDistance(q));
          }
    if (closest < margin)
      warnings.add(file + ": /objects/" + std::to_string(json_index[i]) +
                   ": the object comes within " + fmt(std::max(closest, 0.0)) +
                   " mm of the volume's boundary (smoothing reach " + fmt(margin) +
                   " mm); rays leaving through it are not refracted there");
  }
  warnings.finish();
}

/// A camera or a point or spot light inside an opaque object sees or lights nothing of the scene
/// (every ray from it starts inside the object and ends at once): legal, but never what is meant,
/// so it is said (and --strict refuses it). The innermost opaque object named is the first found.
static void warnInsideOpaque(Scene& scene, const std::vector<size_t>& json_index,
                             const std::string& file) {
  auto opaqueAround = [&](const glm::dvec3& p) -> std::optional<size_t> {
    for (size_t i = 0; i < scene.objects.size(); ++i) {
      const SceneObject& o = scene.objects[i];
      if (scene.materials.at(o.material).opacity >= 0.5 && o.shape.contains(p)) return i;
    }
    return std::nullopt;
  };
  auto where = [&](size_t i) {
    return "inside the opaque object /objects/" + std::to_string(json_index[i]) + " ('" +
           excerpt(scene.objects[i].material) + "')";
  };
  const glm::dvec3 c = scene.camera.position;
  if (auto i = opaqueAround(c))
    scene.warnings.push_back(printable(file + ": /camera/position: the camera at (" + fmt(c.x) +
                                       ", " + fmt(c.y) + ", " + fmt(c.z) + ") is " + where(*i) +
                                       ": every ray starts there and the image is black"));
  for (size_t k = 0; k < scene.lights.size(); ++k) {
    const Light& l = scene.lights[k];
    if (l.type == Light::Type::Directional) continue;
    if (auto i = opaqueAround(l.position))
      scene.warnings.push_back(
          printable(file + ": /lights/" + std::to_string(k) + "/position: the light at (" +
                    fmt(l.position.x) + ", " + fmt(l.position.y) + ", " + fmt(l.position.z) +
                    ") is " + where(*i) + ": none of its light reaches the rest of the scene"));
  }
}

/// A material no object uses is left out (it was parsed and checked like the others): the
/// volume's features (dispersive, attenuating, scattering, uniaxial…) are those of its materials,
/// so an unused dispersive material would make a render spectral and its light 12 bands. Not a
/// warning: a scene may keep a palette of materials to switch between, and --strict must pass.
static void dropUnusedMaterials(Scene& scene) {
  std::set<std::string> used;
  for (const SceneObject& o : scene.objects) used.insert(o.material);
  std::erase_if(scene.materials, [&](const auto& m) { return !used.count(m.first); });
}

// "render": the scene's intended quality (docs/scene-format.md), as `eikon render` checks its
// options (--spp, --wavelengths, --exposure).
static RenderHints parseRenderHints(const Node& r) {
  r.allowKeys({"spp", "wavelengths", "exposure"});
  RenderHints h;
  if (auto s = r.get("spp")) h.spp = s->integer(1, 4096);
  if (auto w = r.get("wavelengths")) h.wavelengths = w->integer(0, 256);
  if (auto e = r.get("exposure")) h.exposure = e->number(-64.0, 64.0);
  return h;
}

// "interfaces": how material boundaries are represented (docs/scene-format.md).
static Scene::Interfaces parseInterfaces(const Node& f) {
  const std::string m = f.string();
  if (m == "sharp") return Scene::Interfaces::Sharp;
  if (m == "smoothed") return Scene::Interfaces::Smoothed;
  f.fail("unknown interfaces '" + excerpt(m) + "' (sharp, smoothed)");
}

Scene parseScene(const std::string& text, const std::filesystem::path& origin) {
  const std::string file = origin.string();
  const json j = parseJson(text, file);
  Scene scene;
  scene.file = origin;
  Node root(j, "", file);
  root.allowKeys({"camera", "environment", "volume", "materials", "objects", "lights",
                  "ambient_index", "description", "interfaces", "render"});
  if (auto c = root.get("camera")) parseCamera(*c, scene.camera);
  if (auto e = root.get("environment")) {
    if (e->has("preset"))
      parseGemEnvironment(*e, scene.camera, scene.environment);
    else
      parseEnvironment(*e, scene.environment);
  }
  if (auto v = root.get("volume")) parseVolume(*v, scene.volume);
  if (auto a = root.get("ambient_index")) scene.ambient_index = a->number(kMinIndex, kMaxIndex);
  if (auto f = root.get("interfaces")) scene.interfaces = parseInterfaces(*f);
  if (auto r = root.get("render")) scene.render = parseRenderHints(*r);
  if (auto ms = root.get("materials")) {
    ms->requireObject();
    for (auto it = ms->raw().begin(); it != ms->raw().end(); ++it)
      scene.materials[it.key()] = parseMaterial(
          Node(it.value(), ms->path() + "/" + excerpt(it.key()), file), it.key(), false);
  }
  std::vector<size_t> json_index;
  const std::set<size_t> covering = parseObjects(root.at("objects"), scene, file, json_index);
  warnObjectsNearFaces(scene, covering, json_index, file);
  dropUnusedMaterials(scene);
  if (auto ls = root.get("lights")) {
    if (!ls->isArray()) ls->fail("expected an array of lights");
    for (size_t i = 0; i < ls->size(); ++i) scene.lights.push_back(parseLight(ls->index(i)));
    // The light simulator's biaxial law is the sharp path's, which needs every region
    // homogeneous (docs/light-simulator.md "Biaxial crystals").
    const bool varying =
        std::any_of(scene.objects.begin(), scene.objects.end(), [&](const auto& o) {
          const auto m = scene.materials.find(o.material);
          return o.radial_axis ||
                 (m != scene.materials.end() && m->second.grin.type != GrinProfile::Type::None);
        });
    if (!scene.lights.empty() && scene.anyBiaxial() && varying)
      ls->fail(
          "lights (the light simulator) are not yet for a biaxial crystal beside a GRIN profile or "
          "an optic-axis field");
  }
  warnInsideOpaque(scene, json_index, file);
  warnUnseenScene(scene, json_index, file);
  return scene;
}

namespace {
json vec3Json(const glm::dvec3& v) { return json::array({v.x, v.y, v.z}); }
}  // namespace

void checkCamera(const Camera& cam, const std::filesystem::path& file) {
  json j = {{"position", vec3Json(cam.position)},
            {"look_at", vec3Json(cam.look_at)},
            {"up", vec3Json(cam.up)},
            {"fov_deg", cam.fov_deg},
            {"width", cam.width},
            {"height", cam.height}};
  if (cam.analyzer) j["analyzer"] = vec3Json(*cam.analyzer);
  Camera parsed;
  parseCamera(Node(j, "/camera", file.string()), parsed);
}

void checkVolumeSpec(const VolumeSpec& vol, const std::filesystem::path& file) {
  const json j = {{"bounds_min", vec3Json(vol.bounds_min)},
                  {"bounds_max", vec3Json(vol.bounds_max)},
                  {"resolution", vol.resolution},
                  {"smoothing_voxels", vol.smoothing_voxels},
                  {"smoothing_method",
                   vol.smoothing == VolumeSpec::Smoothing::Gaussian ? "gaussian" : "analytic"}};
  VolumeSpec parsed;
  parseVolume(Node(j, "/volume", file.string()), parsed);
}

Scene loadScene(const std::filesystem::path& path) {
  return parseScene(readSceneText(path, "a scene file"), path);
}

}  // namespace eikon
