// The double-precision CPU oracle of the view renderer (docs/design.md §1: "the same physics exists
// twice"). It integrates the same ray equation as shaders/march.glsl — dx/ds = w/n, dw/ds = ∇n
// with Euler, midpoint or RK4, straight steps through homogeneous regions, Fresnel at interface
// layers — in double precision, multi-threaded, sharing no code with core/render. It marches
// either the voxelised VolumeSet (so that GPU and CPU see identical fields) or an analytic
// index field (so that the integrator itself can be checked against closed forms without
// voxelisation error).
//
//   eikon::VolumeField field(volume);
//   eikon::ReferenceMarcher ref(field, scene.environment);
//   eikon::TraceOutcome t = ref.trace({{0, 0, -30}, {0, 0, 1}, 587.56}, {});
//   eikon::RenderImage img = ref.render(scene.camera, settings);
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "core/contract/light_tree.h"
#include "core/contract/march_types.h"
#include "core/scene/scene.h"
#include "core/volume/field.h"
#include "core/volume/volume_set.h"

namespace eikon {

/// An analytic, non-absorbing index field n(x) with its exact gradient, inside a box.
class AnalyticField : public Field {
 public:
  using IndexFn = std::function<void(const glm::dvec3&, double&, glm::dvec3&)>;
  AnalyticField(IndexFn fn, glm::dvec3 bmin, glm::dvec3 bmax, double cell)
      : fn_(std::move(fn)), bmin_(bmin), bmax_(bmax), cell_(cell) {}
  void index(const glm::dvec3& x, double, double, double& n, glm::dvec3& grad) const override {
    fn_(x, n, grad);
  }
  glm::dvec4 medium(const glm::dvec3&) const override { return glm::dvec4(0.0); }
  glm::dvec3 emission(const glm::dvec3&) const override { return glm::dvec3(0.0); }
  double skipDistance(const glm::dvec3&) const override { return 0.0; }
  glm::dvec3 boundsMin() const override { return bmin_; }
  glm::dvec3 boundsMax() const override { return bmax_; }
  double cellSize() const override { return cell_; }

 private:
  IndexFn fn_;
  glm::dvec3 bmin_, bmax_;
  double cell_;
};

/// A face a view sample's path met inside a crystal, where its mode may convert
/// (ReferenceMarcher::samplePath): where, whether it reflected (total: nothing was transmitted),
/// and the path's mode (0: o or fast, 1: e or slow) and region after it.
struct PathEvent {
  glm::dvec3 point{0.0};
  bool reflected = false, total = false;
  int mode = 0, region = 0;
};

struct HeroRecord;  // hero wavelength sampling's record of one pixel sample (the .cpp)
class LayerSums;    // core/contract/render_layers.h

class ReferenceMarcher {
 public:
  ReferenceMarcher(const Field& field, const Environment& env) : field_(field), env_(env) {}

  /// Trace one ray at its wavelength in mode 0 (o, or the isotropic ray) or 1 (e).
  TraceOutcome trace(const TraceRequest& ray, const MarchSettings& settings, int mode = 0) const;
  /// The light tree of one ray at its wavelength in mode 0 (o, or the isotropic ray) or 1 (e)
  /// (core/contract/light_tree.h): every Fresnel split followed both ways, by re-marching the
  /// ray with the reflect/refract choices of each branch forced (O(depth) marches per leaf).
  LightTree lightTree(const TraceRequest& ray, const MarchSettings& settings, int mode,
                      const LightTreeSettings& tree) const;
  /// The faces met inside a crystal by the full-transport path of one view sample (the sharp
  /// march; Transport::Full, every choice drawn from transportUniform(seed, k)), in order: the
  /// mode conversion's record, for tests. Empty for the smoothed march.
  std::vector<PathEvent> samplePath(const TraceRequest& ray, const MarchSettings& settings,
                                    int mode, uint32_t seed) const;
  /// Render the camera view, multi-threaded (threads = 0: hardware concurrency).
  RenderImage render(const Camera& camera, const RenderSettings& settings, int threads = 0) const;

 private:
  struct Result;
  struct SampleTally;  // the marches of one pixel sample (the .cpp)
  Result march(const glm::dvec3& o, const glm::dvec3& d, double lambda_nm, bool scalar,
               const MarchSettings& m, int mode, HeroRecord* hero = nullptr, uint32_t seed = 0,
               FirstChoice first = FirstChoice::Drawn) const;
  /// One mode's march of a view sample (the view kernel's marchModes): with Transport::Full its
  /// first Fresnel choice split (FirstChoice), the two branches' radiance summed, both marches
  /// added to `tally` (steps shared by `share` wavelengths). A hero record restarts per branch.
  Result marchSample(const glm::dvec3& o, const glm::dvec3& d, double lambda_nm, bool scalar,
                     const MarchSettings& m, int mode, HeroRecord* hero, uint32_t seed,
                     SampleTally& tally, double share) const;
  /// CIE XYZ (unnormalised, as Σ L·sampleWeightXyz) of one pixel sample by hero wavelength
  /// sampling (docs/spectra.md); adds its marches to `tally`, and its bins to `layers`.
  glm::dvec3 heroSampleXyz(const glm::dvec3& o, const glm::dvec3& d, uint32_t pixel,
                           uint32_t sample, const RenderSettings& s, SampleTally& tally,
                           LayerSums* layers) const;
  /// Linear sRGB of one pixel sample in RGB mode: one march per mode at the index wavelength
  /// (view.comp renderRgbSample).
  glm::dvec3 rgbSample(const glm::dvec3& eye, const glm::dvec3& d, uint32_t pixel, uint32_t sidx,
                       const RenderSettings& s, SampleTally& tally, LayerSums* layers) const;
  /// CIE XYZ (as heroSampleXyz's) of one pixel sample at its N stratified wavelengths, one march
  /// per wavelength and mode (view.comp renderSpectralSample, stratified).
  glm::dvec3 stratifiedSampleXyz(const glm::dvec3& eye, const glm::dvec3& d, uint32_t pixel,
                                 uint32_t sidx, const RenderSettings& s, SampleTally& tally,
                                 LayerSums* layers) const;
  /// Linear sRGB of one pixel sample along d from eye (hero, stratified or RGB) of the modes
  /// settings.modes selects (modeRange), its marches added to `tally` and their radiance to
  /// `layers`.
  glm::dvec3 sampleRgb(const glm::dvec3& eye, const glm::dvec3& d, uint32_t pixel, uint32_t sidx,
                       const RenderSettings& s, bool hero, SampleTally& tally,
                       LayerSums& layers) const;
  const Field& field_;
  const Environment& env_;
};

}  // namespace eikon
