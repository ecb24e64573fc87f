#include "core/session/light_tree_json.h"

namespace eikon {
namespace {

nlohmann::json vec(const glm::dvec3& v) { return nlohmann::json::array({v.x, v.y, v.z}); }

nlohmann::json orNull(int v) { return v < 0 ? nlohmann::json(nullptr) : nlohmann::json(v); }

/// One node: the fields every node has, then those of its kind (fresnel_r at a crossing, cut at
/// a cut leaf, object where the interfaces are sharp).
nlohmann::json nodeJson(const LightTree& t, const LightTreeNode& n) {
  nlohmann::json j = {{"id", n.id},
                      {"parent", orNull(n.parent)},
                      {"event", treeEventName(n.event)},
                      {"point", vec(n.point)},
                      {"direction", vec(n.direction)},
                      {"wave_normal", vec(n.wave_normal)},
                      {"weight", n.weight},
                      {"optical_path_mm", n.optical_path_mm},
                      {"depth", n.depth}};
  if (n.event == TreeEvent::Reflect || n.event == TreeEvent::Refract || n.event == TreeEvent::Tir)
    j["fresnel_r"] = n.fresnel_r;
  if (n.event == TreeEvent::Cut) j["cut"] = treeCutName(n.cut);
  if (t.sharp) j["object"] = orNull(n.object);
  return j;
}

}  // namespace

nlohmann::json lightTreesJson(const TraceRequest& ray, const LightTreeSettings& limits,
                              const std::vector<LightTree>& trees, const std::string& device) {
  nlohmann::json j;
  j["ray"] = {{"origin", vec(ray.origin)},
              {"direction", vec(ray.direction)},
              {"wavelength_nm", ray.wavelength_nm}};
  j["limits"] = {{"min_weight", limits.min_weight},
                 {"max_depth", limits.max_depth},
                 {"max_nodes", limits.max_nodes}};
  j["trees"] = nlohmann::json::array();
  for (const LightTree& t : trees) {
    nlohmann::json tj;
    tj["mode"] = !t.uniaxial ? "isotropic" : modeName(t.mode, t.fast_slow);
    tj["nodes"] = nlohmann::json::array();
    tj["exits"] = nlohmann::json::array();
    for (const LightTreeNode& n : t.nodes) {
      tj["nodes"].push_back(nodeJson(t, n));
      if (n.event == TreeEvent::Exit) tj["exits"].push_back(n.id);
    }
    tj["totals"] = {
        {"exit", t.exit}, {"stopped", t.stopped}, {"absorbed", t.absorbed}, {"cut", t.cut}};
    tj["marches"] = t.marches;
    j["trees"].push_back(tj);
  }
  j["device"] = device;
  return j;
}

}  // namespace eikon
