// The viewer's lighting key (docs/viewer.md "Lighting presets"): `eikon view` shows the scene
// under its own environment or under one of the gem studio's standard presets
// (core/scene/gem_lighting.h: dome, spot, aset, idealscope, lightbox), each built for the current
// camera as `eikon gem` builds it for its observer, and gives the live figures of the scene's
// stone (its first transparent object) under it, measured as the analysis measures a tilt
// (core/session/gem.h measureGemView): brightness and extinction under dome, fire and flashes
// under spot, windowing under idealscope.
//
//   eikon::ViewerLighting lighting(session);
//   lighting.next();                        // the scene's own → dome
//   lighting.update(true);                  // before a render: the preset for the camera now
//   rs.aov_layer = lighting.wantsAov();     // the figures need the stone's pixels
//   std::string f = lighting.figures(img);  // "dome: brightness 0.62, extinction 0.18"
#pragma once

#include <optional>
#include <string>

#include "core/contract/march_types.h"
#include "core/scene/gem_lighting.h"
#include "core/scene/scene.h"

namespace eikon {

class Session;

class ViewerLighting {
 public:
  /// Keeps the scene's own environment to come back to.
  explicit ViewerLighting(Session& session);
  /// The scene's own → dome → spot → aset → idealscope → lightbox → the scene's own.
  void next();
  /// Before a render: a preset just chosen is built for the scene's camera now (the scene's own
  /// comes back after the last); with `follow_camera`, a preset shown is built again where the
  /// camera moved since. The session's renderers take the new environment
  /// (Session::environmentChanged). A build takes ~0.2 s (1024 × 512 texels), so the viewer's
  /// coarse frames, shown while the view is dragged, keep the frame the preset was built for.
  void update(bool follow_camera);
  /// "scene" or the preset's name.
  std::string name() const;
  /// The current preset gives figures (dome, spot, idealscope) and the scene has a stone: renders
  /// should carry the AOV layer (RenderSettings::aov_layer), which tells the stone's pixels.
  bool wantsAov() const;
  /// The figures of `img` (a render of the current view with the AOV layer) under the current
  /// preset, e.g. "dome: brightness 0.620, extinction 0.180"; "dome: the stone is not in view";
  /// just the preset's name where it gives none (aset, lightbox); empty for the scene's own.
  std::string figures(const RenderImage& img) const;

 private:
  Session& session_;
  Environment own_;
  std::optional<GemPreset> preset_;
  std::optional<size_t> stone_;
  bool stale_ = false;
  Camera built_for_;  ///< the camera the preset was last built for
};

}  // namespace eikon
