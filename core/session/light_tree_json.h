// The light trees of one ray as JSON, the shape `eikon trace --tree` prints and Python's
// Renderer.light_tree returns (docs/design.md §3 "eikon trace --tree").
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/contract/light_tree.h"
#include "core/contract/march_types.h"

namespace eikon {

/// {"ray", "limits", "trees": [{"mode", "nodes", "exits", "totals", "marches"}, ...], "device"}.
nlohmann::json lightTreesJson(const TraceRequest& ray, const LightTreeSettings& limits,
                              const std::vector<LightTree>& trees, const std::string& device);

}  // namespace eikon
