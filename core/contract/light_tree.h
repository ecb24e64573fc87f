// The light tree of one ray (`eikon trace --tree`, docs/design.md §3): from the ray, at every
// crossing where the Fresnel equations split the light, both branches are followed — the
// reflection with the branch's weight × R, the refraction with × (1 − R) — and a total internal
// reflection is one branch of weight × 1. Attenuation multiplies the weight along the way. A
// branch ends where it leaves the volume (an exit leaf), on an opaque surface (a stop leaf), or is
// cut: its weight below LightTreeSettings::min_weight, its events past ::max_depth, the march's
// max_steps spent, or the tree's ::max_nodes reached. The weights balance exactly:
// Σ exit + Σ stopped + absorbed + Σ cut = 1 (LightTree's totals). The CPU twin traces it
// (ReferenceMarcher::lightTree), in double precision, by the view march's own crossing code.
#pragma once

#include <glm/glm.hpp>
#include <stdexcept>
#include <vector>

namespace eikon {

struct LightTreeSettings {
  double min_weight = 1e-6;  ///< a branch whose weight falls below this is cut
  int max_depth = 64;        ///< events (reflect, refract, tir) a branch takes before it is cut
  /// The tree's size limit: once it has this many nodes every further event is cut, and the
  /// branches under way end with a leaf each (a small multiple of it bounds the tree).
  int max_nodes = 100000;
};

/// The ranges both the CLI and Python refuse (std::invalid_argument, one line): min_weight in
/// [1e-15, 1], max_depth in [1, 1024], max_nodes in [1, 10⁶].
inline void checkLightTreeSettings(const LightTreeSettings& s) {
  if (!(s.min_weight >= 1e-15 && s.min_weight <= 1.0))
    throw std::invalid_argument("tree min weight must be in [1e-15, 1]");
  if (s.max_depth < 1 || s.max_depth > 1024)
    throw std::invalid_argument("tree max depth must be in [1, 1024] events");
  if (s.max_nodes < 1 || s.max_nodes > 1000000)
    throw std::invalid_argument("tree max nodes must be in [1, 1000000]");
}

/// What happened at a node: where the ray entered the volume (the root), a branch's event at a
/// crossing, or how a branch ended (a leaf).
enum class TreeEvent { Enter, Reflect, Refract, Tir, Exit, Stop, Cut };
inline const char* treeEventName(TreeEvent e) {
  constexpr const char* kNames[] = {"enter", "reflect", "refract", "tir", "exit", "stop", "cut"};
  return kNames[int(e)];
}
/// Why a branch was cut.
enum class TreeCut { None, Weight, Depth, Steps, Nodes };
inline const char* treeCutName(TreeCut c) {
  constexpr const char* kNames[] = {"", "weight", "depth", "steps", "nodes"};
  return kNames[int(c)];
}

struct LightTreeNode {
  int id = 0, parent = -1;  ///< parent: -1 at the root; a parent's id is below its children's
  TreeEvent event = TreeEvent::Enter;
  /// Where it happened (a cut: where the branch was cut; a crossing's reflection is at the
  /// crossing).
  glm::dvec3 point{0.0};
  /// The ray (energy) direction and the wave normal leaving the node (exit: leaving the volume;
  /// a stop or cut leaf: arriving there).
  glm::dvec3 direction{0.0}, wave_normal{0.0};
  double weight = 0.0;           ///< the branch's share of the incident light leaving the node
  double fresnel_r = 0.0;        ///< reflect, refract: the crossing's reflectance R; tir: 1
  double optical_path_mm = 0.0;  ///< ∫ n ds (the phase path p·dx for the e-mode) from the origin
  int object = -1;  ///< sharp interfaces: the object the branch is in after the node (-1: none)
  int depth = 0;    ///< reflect, refract and tir events from the root up to this node
  TreeCut cut = TreeCut::None;  ///< a cut leaf's reason
};

struct LightTree {
  int mode = 0;                      ///< 0: the o-mode (or the isotropic ray), 1: the e-mode
  bool uniaxial = false;             ///< the scene has crystals: every node is in `mode`
  bool fast_slow = false;            ///< its crystals are all biaxial: modes named fast, slow
  bool sharp = false;                ///< sharp interfaces (LightTreeNode::object is known)
  std::vector<LightTreeNode> nodes;  ///< the root first, parents before children
  double exit = 0.0, stopped = 0.0, absorbed = 0.0, cut = 0.0;  ///< the weights' balance
  int marches = 0;  ///< marches the tracer ran (one per branch reflected)
};

}  // namespace eikon
