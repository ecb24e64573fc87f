// The GPU view renderer: uploads a VolumeSet into 3D images and marches viewing rays through it
// with the ray equation (shaders/march.glsl). Its double-precision twin is
// core/reference/reference_marcher.h; tests hold the two to each other.
//
//   auto ctx = eikon::vk::Context::create();
//   eikon::Scene scene = eikon::loadScene("scenes/glass_sphere.json");
//   eikon::checkVolumeFits(*ctx, eikon::makeGrid(scene.volume), scene);   // refuse before
//   voxelising eikon::VolumeSet vol = eikon::voxelize(scene); eikon::ViewRenderer renderer(*ctx,
//   scene, vol); eikon::RenderImage img = renderer.render({});
//
// Common mistakes: voxelising before checkVolumeFits (a 4096³ request would exhaust host memory
// before the device refuses it); comparing timings across runs (lavapipe varies ±20%).
#pragma once

#include <array>
#include <memory>
#include <vector>

#include "core/contract/march_types.h"
#include "core/contract/polarised.h"
#include "core/scene/scene.h"
#include "core/vk/context.h"
#include "core/vk/resources.h"
#include "core/volume/volume_set.h"

namespace eikon {

/// Throw a one-line std::runtime_error if the scene's volume cannot live on this device
/// (3D image side limit, heap size). Call before voxelising.
void checkVolumeFits(const vk::Context& ctx, const Grid& grid, const Scene& scene);

/// The GPU twin's polarised render and trace take at most EIKON_POL_MAX_SHEETS (8) polariser
/// sheets (shaders/polarised_trace.comp looks through every sheet for the next one along each
/// straight piece of a path); the CPU twin takes any number. Throws a one-line std::runtime_error
/// "FILE: /objects/N: ..." naming the first sheet beyond the limit and the CPU twin as the remedy
/// when the scene has more. Call before voxelising; Session::render and Session::tracePolarised
/// call it for the GPU twin.
void checkGpuPolariserSheets(const Scene& scene);

class ViewRenderer {
 public:
  /// `expected`: the settings of the render that will follow, if known; its view pipeline is then
  /// compiled on a thread of its own while the volume is uploaded (start-up, docs/performance.md).
  ViewRenderer(vk::Context& ctx, const Scene& scene, const VolumeSet& volume,
               const RenderSettings* expected = nullptr);
  ~ViewRenderer();
  ViewRenderer(const ViewRenderer&) = delete;
  ViewRenderer& operator=(const ViewRenderer&) = delete;

  /// Render the scene's camera view. Throws std::invalid_argument for bad settings.
  RenderImage render(const RenderSettings& settings);
  /// Compile the view pipeline a render with `settings` needs on a thread of its own, unless it
  /// is built or asked for already: one compile at a time, in the order asked (the viewer asks
  /// for those of its keys ahead; docs/viewer.md). render() adopts it, or waits for it while it
  /// compiles.
  void prefetch(const RenderSettings& settings);
  /// Whether render(settings) starts without compiling its view pipeline (built, or compiled in
  /// the background). On lavapipe the first dispatch of a new pipeline may still compile machine
  /// code that Mesa's shader cache does not hold yet.
  bool ready(const RenderSettings& settings);
  /// The scene's environment changed (the viewer's lighting key): its image is uploaded again and
  /// bound to every pipeline built. Renders after it see the new environment; a change of kind
  /// (checker, constant, image) takes another view pipeline, compiled at the next render.
  void environmentChanged();
  /// Write `volume`'s light volumes (the same grid; a light moved and simulated again: the
  /// viewer) into the images this renderer reads, in place: no pipeline is built again. False,
  /// changing nothing, when this renderer was made without light volumes or `volume` has none
  /// (a new renderer is needed then).
  bool updateLight(const VolumeSet& volume);
  /// Trace individual rays at their wavelengths: the o-mode (isotropic scenes: the ray).
  std::vector<TraceOutcome> trace(const std::vector<TraceRequest>& rays,
                                  const MarchSettings& settings);
  /// Trace both modes of each ray: {o, e}; identical where every material is isotropic.
  std::vector<std::array<TraceOutcome, 2>> traceModes(const std::vector<TraceRequest>& rays,
                                                      const MarchSettings& settings);
  /// The polarised trace of each ray through the scene's sharp boundaries and `sheets` (the GPU
  /// twin of core/reference/polarised_trace.h's tracePolarised; shaders/polarised_trace.comp):
  /// inputs[i] is ray i's input Stokes vector. Throws std::invalid_argument as the CPU twin does
  /// (and for more than 8 sheets or a ray/input count mismatch), std::runtime_error for a scene
  /// without sharp interfaces or a path through a region the trace does not support. seeds[i]
  /// draws ray i's Transport::Full choices (empty: seed 0 for every ray).
  std::vector<PolarisedTrace> tracePolarised(const std::vector<PolarizerSheet>& sheets,
                                             const std::vector<TraceRequest>& rays,
                                             const std::vector<Stokes>& inputs,
                                             const PolarisedTraceSettings& settings = {},
                                             const std::vector<std::uint32_t>& seeds = {});
  /// A polarised render of the scene's camera (core/contract/polarised_render.h, the GPU twin of
  /// core/reference/polarised_render.h): rgb = S0 after the camera's analyser, stokes layers if
  /// asked. Throws as renderPolarisedWith and tracePolarised (at most 8 polariser sheets).
  RenderImage renderPolarised(const RenderSettings& settings,
                              const PolarisedTraceSettings& trace = {});

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace eikon
