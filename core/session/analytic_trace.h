// Rays through an exact index field n(x), ∇n(x) given as a function in a box, traced by the CPU
// twin (core/reference ReferenceMarcher over an AnalyticField) without voxelising: Python's
// eikon.AnalyticField (python/module_analytic.cpp), which checks the field's arguments; the
// session only marches.
//
//   eikon::AnalyticTrace luneburg(
//       [](const glm::dvec3& x, double& n, glm::dvec3& g) { ... }, {-12, -12, -12}, {12, 12, 12},
//       0.1);
//   TraceOutcome o = luneburg.trace({{-11, 0, 0}, {1, 0, 0}, 587.56}, MarchSettings{});
#pragma once

#include <functional>
#include <memory>

#include "core/scene/scene.h"
#include "core/session/session.h"

namespace eikon {

class AnalyticField;

class AnalyticTrace {
 public:
  /// n and ∇n at a point; called from the marching thread, once per sample.
  using IndexFn = std::function<void(const glm::dvec3& x, double& n, glm::dvec3& grad)>;
  /// The field in the box [bmin, bmax]; `cell` (mm) is the voxel that MarchSettings::step_voxels
  /// is measured in. Rays leave into the default Environment.
  AnalyticTrace(IndexFn fn, glm::dvec3 bmin, glm::dvec3 bmax, double cell);
  ~AnalyticTrace();
  AnalyticTrace(const AnalyticTrace&) = delete;
  AnalyticTrace& operator=(const AnalyticTrace&) = delete;

  /// One ray in mode o (the isotropic ray), as Session::trace's CPU twin marches it.
  TraceOutcome trace(const TraceRequest& ray, const MarchSettings& settings) const;

 private:
  std::unique_ptr<AnalyticField> field_;
  Environment env_;
};

}  // namespace eikon
