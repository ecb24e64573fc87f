#include "core/reference/polarised_render.h"

#include <algorithm>
#include <atomic>
#include <exception>
#include <mutex>
#include <thread>

#include "core/contract/polarised_render.h"
#include "core/reference/polarised_trace.h"

namespace eikon {

RenderImage renderPolarised(const Field& field, const Scene& scene, const RenderSettings& settings,
                            int threads, const PolarisedTraceSettings& trace) {
  const int workers =
      threads > 0 ? threads : int(std::max(1u, std::thread::hardware_concurrency()));
  auto batch = [&](const std::vector<TraceRequest>& rays, const std::vector<std::uint32_t>& seeds,
                   const PolarisedTraceSettings& ts) {
    std::vector<PolarisedTrace> out(rays.size());
    std::atomic<size_t> next{0};
    std::exception_ptr error;
    std::mutex error_mutex;
    auto work = [&] {
      for (size_t i = next++; i < rays.size(); i = next++) {
        try {
          out[i] = tracePolarised(field, scene.polarizers, rays[i], {1, 0, 0, 0}, ts, seeds[i]);
        } catch (...) {
          std::lock_guard<std::mutex> lock(error_mutex);
          if (!error) error = std::current_exception();
          next = rays.size();
        }
      }
    };
    std::vector<std::thread> pool;
    for (int t = 0; t < workers; ++t) pool.emplace_back(work);
    for (std::thread& t : pool) t.join();
    if (error) std::rethrow_exception(error);
    return out;
  };
  return renderPolarisedWith(scene, settings, batch, trace);
}

}  // namespace eikon
