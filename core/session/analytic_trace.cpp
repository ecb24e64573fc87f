#include "core/session/analytic_trace.h"

#include "core/reference/reference_marcher.h"

namespace eikon {

AnalyticTrace::AnalyticTrace(IndexFn fn, glm::dvec3 bmin, glm::dvec3 bmax, double cell)
    : field_(std::make_unique<AnalyticField>(std::move(fn), bmin, bmax, cell)) {}

AnalyticTrace::~AnalyticTrace() = default;

TraceOutcome AnalyticTrace::trace(const TraceRequest& ray, const MarchSettings& settings) const {
  return ReferenceMarcher(*field_, env_).trace(ray, settings);
}

}  // namespace eikon
