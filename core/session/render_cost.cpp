// The cost of a render, said before it starts: see render_cost.h.
#include "core/session/render_cost.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>

#include "core/session/session.h"
#include "core/volume/host_memory.h"

namespace eikon {

RenderCost renderWork(const Scene& scene, const RenderSettings& settings) {
  RenderCost c;
  c.width = settings.width > 0 ? settings.width : scene.camera.width;
  c.height = settings.height > 0 ? settings.height : scene.camera.height;
  c.spp = settings.spp;
  c.wavelengths = settings.wavelengths;
  c.samples =
      double(c.width) * double(c.height) * double(c.spp) * double(std::max(1, c.wavelengths));
  c.host_bytes = renderHostBytes(scene, settings);
  c.write_seconds = double(c.width) * double(c.height) * kWriteSecondsPerPixel;
  return c;
}

bool worthATrial(const RenderCost& cost) { return cost.samples >= kRenderTrialMinSamples; }

namespace {
/// Time of session.render(trial): the march's own where the twin measures it, else the wall time.
double timedRender(Session& session, const RenderSettings& trial, bool gpu) {
  const auto t0 = std::chrono::steady_clock::now();
  const RenderImage img = session.render(trial, gpu);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return img.seconds > 0 ? img.seconds : wall;
}
}  // namespace

void timeRenderTrial(Session& session, const RenderSettings& settings, bool gpu, RenderCost& cost) {
  RenderSettings trial = settings;
  trial.progress = [](double) {};  // the session's progress is the real render's
  trial.on_pass = nullptr;
  // A few pixels at one sample first: on the GPU the first render builds the pipelines and
  // uploads the volume (not the march's cost); the next gives the fixed cost of a render
  // (dispatches, read-back, threads), which the trial would otherwise scale up 64 times (twice
  // the time of a GPU render of calcite_rhomb on lavapipe).
  trial.width = std::min(cost.width, 8);
  trial.height = std::min(cost.height, 8);
  trial.spp = 1;
  if (gpu) (void)session.render(trial, true);
  const double fixed = timedRender(session, trial, gpu);
  const double fixed_samples = double(trial.width) * trial.height;
  // An eighth of each side, rounded so that the trial keeps the image's aspect; an image too
  // small for that (a few pixels at thousands of samples) keeps its size and takes 1/64 of the
  // samples instead.
  trial.width = std::max(1, int(std::lround(cost.width / 8.0)));
  trial.height = std::max(1, int(std::lround(cost.height / 8.0)));
  trial.spp = settings.spp;
  if (16.0 * trial.width * trial.height > double(cost.width) * cost.height) {
    trial.width = cost.width;
    trial.height = cost.height;
    trial.spp = std::max(1, settings.spp / 64);
  }
  cost.on_gpu = gpu;
  cost.trial_width = trial.width;
  cost.trial_height = trial.height;
  cost.trial_seconds = timedRender(session, trial, gpu);
  const double trial_samples = double(trial.width) * trial.height * trial.spp;
  const double scale = double(cost.width) * cost.height * settings.spp / trial_samples;
  // The fixed cost is taken out only where it is a small part of the trial's work.
  const double base =
      trial_samples >= 16.0 * fixed_samples ? std::min(fixed, cost.trial_seconds) : 0.0;
  cost.seconds = base + (cost.trial_seconds - base) * scale;
  cost.low = kRenderCostLow * cost.seconds;
  cost.high = kRenderCostHigh * cost.seconds;
}

std::string formatDuration(double s) {
  char buf[48];
  if (s < 60)
    std::snprintf(buf, sizeof buf, "%.1f s", s);
  else if (s < 3600)
    std::snprintf(buf, sizeof buf, "%d min %02d s", int(s / 60), int(s) % 60);
  else
    std::snprintf(buf, sizeof buf, "%d h %02d min", int(s / 3600), int(s / 60) % 60);
  return buf;
}

std::string describeRenderCost(const RenderCost& c) {
  char work[160];
  std::snprintf(
      work, sizeof work, "render %dx%d px x %d spp x %s = %.3g M samples, up to %s of host memory",
      c.width, c.height, c.spp,
      c.wavelengths > 0 ? (std::to_string(c.wavelengths) + " wavelengths").c_str() : "RGB",
      c.samples / 1e6, formatBytes(c.host_bytes).c_str());
  std::string line = work;
  if (c.seconds > 0) {
    char trial[64];
    std::snprintf(trial, sizeof trial, "%dx%d", c.trial_width, c.trial_height);
    line += "; about " + formatDuration(c.seconds) + " (" + formatDuration(c.low) + " to " +
            formatDuration(c.high) + ") on the " + (c.on_gpu ? "GPU" : "CPU reference") +
            ", timed on a " + trial + " trial (" + formatDuration(c.trial_seconds) + ")";
  }
  if (c.write_seconds >= 1.0)
    line += "; about " + formatDuration(c.write_seconds) + " to write the EXR and PNG";
  return line;
}

}  // namespace eikon
