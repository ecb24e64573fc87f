// What a render will cost, said before it starts: the work (pixels × samples × wavelengths), the
// host memory it holds, and its time, measured on a trial render of the same scene, settings and
// camera at an eighth of the width and height (1/64 of the pixels, so ~1.5% of the render's time;
// the fixed cost of a render, measured on 8×8 pixels, is not scaled):
// the march's cost per pixel sample varies with the scene (steps per ray, branches at crystal
// faces, the device) far more than any fixed model could say, and a smaller image of the same view
// meets the same objects in the same proportions.
//
//   RenderCost cost = renderWork(scene, settings);          // no rendering
//   if (worthATrial(cost)) timeRenderTrial(session, settings, gpu, cost);
//   if (cost.seconds >= 10) puts(describeRenderCost(cost).c_str());
//
// The estimate's uncertainty (kRenderCostLow/High) is measured, not modelled: the ratio of the
// render's time to the estimate lay in [0.74, 1.58] on the README's scenes, both twins, on a
// shared 2-core machine (docs/cost-estimates.md); a machine busier during the
// trial than during the render (or the reverse) moves it further.
#pragma once

#include <string>

#include "core/contract/march_types.h"
#include "core/scene/scene.h"

namespace eikon {

class Session;

struct RenderCost {
  int width = 0, height = 0, spp = 1, wavelengths = 0;
  double samples = 0;     ///< pixel samples × wavelengths (× 1 in RGB): the marches' work
  double host_bytes = 0;  ///< renderHostBytes: the image and its copies at the peak
  bool on_gpu = false;
  int trial_width = 0, trial_height = 0;  ///< 0: no trial ran
  double trial_seconds = 0;               ///< the trial's march
  double seconds = 0;                     ///< estimated time of the render (0: not estimated)
  double low = 0, high = 0;               ///< the range the time is expected in
  double write_seconds = 0;  ///< writing the EXR and PNG: pixels × kWriteSecondsPerPixel
};

/// Writing an RGB EXR and its PNG preview, per pixel: 6.7 s for 4096×3072 on a 2-core machine;
/// layers add their channels to the EXR.
inline constexpr double kWriteSecondsPerPixel = 0.53e-6;

/// The measured spread of a render's time about the trial's estimate (see the header comment).
inline constexpr double kRenderCostLow = 0.7, kRenderCostHigh = 1.6;
/// Renders with fewer samples than this are not timed: at most a few seconds on either twin.
inline constexpr double kRenderTrialMinSamples = 1 << 20;

/// The work and memory of a render (the scene camera's size where the settings leave it 0).
RenderCost renderWork(const Scene& scene, const RenderSettings& settings);
/// Whether a trial is worth its time (samples ≥ kRenderTrialMinSamples).
bool worthATrial(const RenderCost& cost);
/// Render the trial (on the session's twin; a GPU trial is run once before, at a few pixels, to
/// build its pipelines untimed) and fill the trial fields, seconds, low and high.
void timeRenderTrial(Session& session, const RenderSettings& settings, bool gpu, RenderCost& cost);
/// "render 800x600 px x 1 spp x 32 wavelengths = 15.4 M samples, up to 46 MB of host memory;
/// about 6 min 40 s (5 min 00 s to 9 min 00 s) on the CPU reference, timed on a 100x75 trial
/// (6.2 s)", and the time to write the files where it is a second or more.
std::string describeRenderCost(const RenderCost& cost);
/// "1.2 s", "6 min 40 s", "2 h 05 min".
std::string formatDuration(double seconds);

}  // namespace eikon
