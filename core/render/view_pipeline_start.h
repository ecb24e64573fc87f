// The view pipeline compiled before the volume exists (start-up; docs/performance.md
// "Start-up"). On lavapipe, building the view kernel's pipeline is SPIR-V → NIR work that no cache
// of Mesa 22.3 keeps (~1 s of CPU for glass_sphere's sharp kernel, every run), the longest stage
// before the first dispatch. Its specialisation (the EIKON_F_* flags) depends on the volume's
// features, which follow from the scene's materials and shapes alone, so `eikon render` starts it
// right after creating the device, on a thread of its own, beside the voxelising (or the volume
// cache's read) and the upload; the ViewRenderer made later adopts it.
//
//   auto early = eikon::startViewPipeline(ctx, scene, /*lit=*/false, settings);  // a thread
//   VolumeSet v = eikon::voxelize(scene);
//   eikon::ViewRenderer r(ctx, scene, v, &settings);   // adopts it at the first dispatch
//   r.render(settings);
//   early.reset();                                     // before the context ends
//
// A prediction that misses (other flags than the volume's) costs the compile's CPU, never a wrong
// kernel: a renderer only adopts a pipeline of its own key.
#pragma once

#include <memory>

#include "core/contract/march_types.h"
#include "core/scene/scene.h"
#include "core/vk/context.h"
#include "core/volume/volume_set.h"

namespace eikon {

/// The EIKON_F_* flags of a volume's features (dispersive, uniaxial, attenuation, emission,
/// opacity, scatter, lit, sharp, and the sharp march's varying / convex / mesh / convex-apart):
/// what the view kernel's specialisation takes from the volume (a render adds its own).
int volumeFeatureFlags(const VolumeSet& volume);

/// The view kernel's kExact constant for a volume (march.glsl: the shape table's rows, shape
/// count and kinds of the exact path), 0 where the volume does not take that path.
int volumeExactConstant(const VolumeSet& volume);

/// volumeFeatureFlags(voxelize(scene)) (with light volumes when `lit`), without voxelising the
/// scene at its resolution: milliseconds.
int predictVolumeFeatureFlags(const Scene& scene, bool lit);

/// Start compiling the view pipeline of a render of `scene` with `settings` on a thread of its
/// own, for the volume voxelize(scene) makes (lit: light volumes will be bound). The first
/// ViewRenderer on `ctx` whose render needs that pipeline takes it instead of compiling its own.
/// Dropping the handle waits for a compile still running: drop it before the context. Nothing is
/// started (nullptr) for settings render() refuses or a polarised render (another kernel).
std::shared_ptr<void> startViewPipeline(vk::Context& ctx, const Scene& scene, bool lit,
                                        const RenderSettings& settings);

}  // namespace eikon
