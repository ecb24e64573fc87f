#include "core/volume/media.h"

#include <algorithm>
#include <cmath>

#include "anisotropic/units.h"
#include "core/scene/scene.h"

namespace eikon {
namespace {

MediumDispersion dispersionRecord(const Dispersion& d) {
  MediumDispersion r;
  r.kind = MediumDispersion::Kind(int(d.kind()));
  const std::vector<double>& a = d.coefficients();
  r.terms = int(std::min<size_t>(a.size(), 6));
  r.coeff.fill(0.0);
  for (size_t k = 0; k < size_t(r.terms); ++k) r.coeff[k] = a[k];
  const std::vector<double>& c = d.sellmeierC();
  for (size_t k = 0; k < std::min<size_t>(c.size(), 6); ++k) r.sellmeier_c[k] = c[k];
  return r;
}

glm::dvec3 bands(const Attenuation& a) { return glm::dvec3(a.at(612.0), a.at(549.0), a.at(465.0)); }

// The 5 nm table of (σ_o, σ_e, σ_beta) where any of the three is a spectrum; else empty.
std::vector<glm::dvec3> sigmaSpectrum(const Attenuation& o, const Attenuation& e,
                                      const Attenuation& beta) {
  std::vector<glm::dvec3> t;
  if (o.wavelengths_nm.empty() && e.wavelengths_nm.empty() && beta.wavelengths_nm.empty()) return t;
  for (int i = 0; i < kSigmaSamples; ++i) {
    const double l = kSigmaFirstNm + i * kSigmaStepNm;
    t.emplace_back(o.at(l), e.at(l), beta.at(l));
  }
  return t;
}

// A biaxial crystal: the principal indices of the material, its axes or the object's (homogeneous;
// the scene refuses GRIN profiles and axis fields on one).
MediumRecord biaxialRecord(const SceneObject& obj, const Material& mat) {
  MediumRecord m;
  m.biaxial = true;
  m.n_o = dispersionRecord(mat.n_alpha);
  m.n_beta = dispersionRecord(mat.n_beta);
  m.n_e = dispersionRecord(mat.n_gamma);
  m.axis = glm::normalize(obj.gamma_axis.value_or(mat.gamma_axis));  // the object's own, if given
  m.alpha_axis = glm::normalize(obj.alpha_axis.value_or(mat.alpha_axis));
  m.sigma_o = bands(mat.attenuation_alpha);
  m.sigma_beta = bands(mat.attenuation_beta);
  m.sigma_e = bands(mat.attenuation_gamma);
  m.sigma_spectrum =
      sigmaSpectrum(mat.attenuation_alpha, mat.attenuation_gamma, mat.attenuation_beta);
  m.opacity = mat.opacity;
  m.emission = mat.emission;
  m.albedo = mat.albedo;
  m.phase_g = mat.phase_g;
  m.homogeneous = true;
  return m;
}

MediumRecord objectRecord(const SceneObject& obj, const Material& mat) {
  MediumRecord m;
  if (mat.biaxial) return biaxialRecord(obj, mat);
  m.n_o = dispersionRecord(mat.n_o);
  m.n_e = mat.uniaxial ? dispersionRecord(mat.n_e) : m.n_o;
  m.n_beta = m.n_o;
  m.uniaxial = mat.uniaxial;
  m.radial_axis = mat.uniaxial && obj.radial_axis;
  if (m.radial_axis)
    m.axis_centre = obj.shape.center();
  else if (mat.uniaxial)
    m.axis = glm::normalize(obj.optic_axis ? *obj.optic_axis : *mat.optic_axis);
  m.sigma_o = bands(mat.attenuation_o);
  m.sigma_e = mat.uniaxial ? bands(mat.attenuation_e) : m.sigma_o;
  m.sigma_beta = m.sigma_o;
  const Attenuation& ae = mat.uniaxial ? mat.attenuation_e : mat.attenuation_o;
  m.sigma_spectrum = sigmaSpectrum(mat.attenuation_o, ae, mat.attenuation_o);
  m.opacity = mat.opacity;
  m.emission = mat.emission;
  m.albedo = mat.albedo;
  m.phase_g = mat.phase_g;
  m.grin_type = int(mat.grin.type);
  m.grin_n0 = mat.grin.n0;
  m.grin_radius = mat.grin.radius;
  m.grin_gradient = mat.grin.gradient;
  m.grin_origin = mat.grin.origin;
  m.homogeneous = m.grin_type == 0 && !m.radial_axis;
  return m;
}

GrinProfile grinOf(const MediumRecord& m) {
  GrinProfile g;
  g.type = GrinProfile::Type(m.grin_type);
  g.n0 = m.grin_n0;
  g.gradient = m.grin_gradient;
  g.origin = m.grin_origin;
  g.radius = m.grin_radius;
  return g;
}

void packDispersion(const MediumDispersion& d, float* v) {
  for (size_t k = 0; k < 6; ++k) {
    v[k] = float(d.coeff[k]);
    v[6 + k] = float(d.sellmeier_c[k]);
  }
}

// Rows 16–21 (the β index, α̂, σ_β).
void packBiaxial(const MediumRecord& m, float* v) {
  v[16 * 4 + 0] = float(int(m.n_beta.kind));
  v[16 * 4 + 1] = float(m.n_beta.terms);
  packDispersion(m.n_beta, v + 17 * 4);
  for (int c = 0; c < 3; ++c) {
    v[20 * 4 + c] = float(m.alpha_axis[c]);
    v[21 * 4 + c] = float(m.sigma_beta[c]);
  }
}

}  // namespace

MediaTable buildMediaTable(const Scene& scene) {
  MediaTable t;
  MediumRecord ambient;
  ambient.n_o.coeff[0] = scene.ambient_index;
  ambient.n_e = ambient.n_o;
  ambient.n_beta = ambient.n_o;
  t.regions.push_back(ambient);
  // Medium ids as the boundary field numbers them (1 + index in scene.materials' order).
  for (const SceneObject& obj : scene.objects) {
    const Material& mat = scene.materials.at(obj.material);
    MediumRecord m = objectRecord(obj, mat);
    m.medium = 1 + int(std::distance(scene.materials.begin(), scene.materials.find(obj.material)));
    t.regions.push_back(m);
  }
  return t;
}

double bandValueAt(const glm::dvec3& rgb, double l) {
  if (l <= 465.0) return rgb.b;
  if (l >= 612.0) return rgb.r;
  if (l <= 549.0) return rgb.b + (rgb.g - rgb.b) * (l - 465.0) / (549.0 - 465.0);
  return rgb.g + (rgb.r - rgb.g) * (l - 549.0) / (612.0 - 549.0);
}

double mediumSigmaAt(const MediumRecord& m, int axis, double lambda_nm) {
  if (m.sigma_spectrum.empty())
    return bandValueAt(axis == 0 ? m.sigma_o : axis == 1 ? m.sigma_e : m.sigma_beta, lambda_nm);
  const double u =
      std::clamp((lambda_nm - kSigmaFirstNm) / kSigmaStepNm, 0.0, double(kSigmaSamples - 1));
  const int i = std::min(int(u), kSigmaSamples - 2);
  const double a = m.sigma_spectrum[size_t(i)][axis], b = m.sigma_spectrum[size_t(i) + 1][axis];
  return a + (b - a) * (u - i);
}

bool fastSlowModes(const MediaTable* table) {
  if (!table) return false;
  bool biaxial = false;
  for (const MediumRecord& m : table->regions) {
    if (m.uniaxial) return false;
    biaxial = biaxial || m.biaxial;
  }
  return biaxial;
}

double mediumIndex(const MediumDispersion& d, double lambda_nm) {
  const double l = micrometresFromNanometres(lambda_nm), l2 = l * l;
  switch (d.kind) {
    case MediumDispersion::Kind::Constant:
      return d.coeff[0];
    case MediumDispersion::Kind::Cauchy: {
      double n = 0.0, p = 1.0;
      for (int k = 0; k < d.terms; ++k, p /= l2) n += d.coeff[size_t(k)] * p;
      return n;
    }
    case MediumDispersion::Kind::Sellmeier: {
      double n2 = 1.0;
      for (int k = 0; k < d.terms; ++k)
        n2 += d.coeff[size_t(k)] * l2 / (l2 - d.sellmeier_c[size_t(k)]);
      return n2 > 0.0 ? std::sqrt(n2) : std::nan("");
    }
    case MediumDispersion::Kind::Conrady:
      return d.coeff[0] + d.coeff[1] / l + d.coeff[2] / (l2 * l * std::sqrt(l));
  }
  return std::nan("");
}

double mediumIndexAt(const MediumRecord& m, int mode, double lambda_nm, const glm::dvec3& x,
                     glm::dvec3* grad) {
  if (grad) *grad = glm::dvec3(0.0);
  if (m.grin_type != 0) {  // a GRIN profile replaces the (isotropic) index
    const GrinProfile g = grinOf(m);
    // Inside its region the profile's own formula, continued smoothly past the surface (RK4's
    // stages may sample just outside): GrinProfile clamps n ≥ 1 there, a kink that would cut
    // the integrator to low order in the last step before a crossing.
    const glm::dvec3 r = x - g.origin;
    const double q = glm::dot(r, r) / (g.radius * g.radius);
    if (g.type == GrinProfile::Type::Luneburg && q < 1.9) {
      const double n = std::sqrt(2.0 - q);
      if (grad) *grad = -r / (g.radius * g.radius * n);
      return n;
    }
    if (g.type == GrinProfile::Type::MaxwellFisheye) {
      if (grad) *grad = -2.0 * g.n0 * r / (g.radius * g.radius * (1.0 + q) * (1.0 + q));
      return g.n0 / (1.0 + q);
    }
    if (grad) *grad = g.indexGradient(x);
    return g.index(x);
  }
  return mediumIndex(mode == 1 ? m.n_e : m.n_o, lambda_nm);
}

glm::dvec4 mediumAxisField(const MediumRecord& m, const glm::dvec3& x) {
  if (!m.uniaxial) return glm::dvec4(0.0);
  if (!m.radial_axis) return glm::dvec4(m.axis, 0.0);
  const glm::dvec3 r = x - m.axis_centre;
  const double len = glm::length(r);
  if (!(len > 1e-12)) return glm::dvec4(0.0, 0.0, 1.0, 0.0);  // the centre: any axis
  return glm::dvec4(r / len, 1.0 / len);
}

std::vector<float> packMediaTable(const MediaTable& table) {
  std::vector<float> out(table.regions.size() * size_t(kMediumVec4s) * 4, 0.0f);
  // The σ spectra after the records; each region's row 21.w is the first row of its block.
  std::vector<float> spectra;
  std::vector<size_t> block(table.regions.size(), 0);
  for (size_t r = 0; r < table.regions.size(); ++r) {
    const std::vector<glm::dvec3>& t = table.regions[r].sigma_spectrum;
    if (t.empty()) continue;
    block[r] = table.regions.size() * size_t(kMediumVec4s) + spectra.size() / 4;
    for (const glm::dvec3& v : t)
      spectra.insert(spectra.end(), {float(v.x), float(v.y), float(v.z), 0.0f});
  }
  for (size_t r = 0; r < table.regions.size(); ++r) {
    const MediumRecord& m = table.regions[r];
    float* v = out.data() + r * size_t(kMediumVec4s) * 4;
    packBiaxial(m, v);
    v[0] = float(int(m.n_o.kind));
    v[1] = float(m.n_o.terms);
    v[2] = float(int(m.n_e.kind));
    v[3] = float(m.n_e.terms);
    packDispersion(m.n_o, v + 4);
    packDispersion(m.n_e, v + 16);
    const int flags = (m.homogeneous ? kMediumHomogeneous : 0) |
                      (m.uniaxial ? kMediumUniaxial : 0) | (m.radial_axis ? kMediumRadialAxis : 0) |
                      (m.grin_type != 0 ? kMediumGrin : 0) | (m.opaque() ? kMediumOpaque : 0) |
                      (m.biaxial ? kMediumBiaxial : 0);
    const glm::dvec4 rows[] = {
        {m.axis, double(flags)},         {m.sigma_o, m.opacity},
        {m.sigma_e, m.phase_g},          {m.emission, double(m.medium)},
        {m.albedo, double(m.grin_type)}, {m.grin_n0, m.grin_gradient},
        {m.grin_origin, m.grin_radius},  {m.axis_centre, 0.0},
    };
    for (size_t i = 0; i < 8; ++i)
      for (int c = 0; c < 4; ++c) v[(7 + i) * 4 + size_t(c)] = float(rows[i][c]);
    v[21 * 4 + 3] = float(block[r]);
  }
  out.insert(out.end(), spectra.begin(), spectra.end());
  return out;
}

}  // namespace eikon
