// The one folder of eikon's on-disk caches: the light volumes (core/light/light_cache.h) and the
// Vulkan pipeline cache (core/vk/pipeline_cache.h). Both follow the same rules so that one
// setting moves (or, for tests, isolates) every cache at once.
#pragma once

#include <filesystem>

namespace eikon {

/// $EIKON_CACHE_DIR, else $XDG_CACHE_HOME/eikon, else $HOME/.cache/eikon; empty when none is set.
std::filesystem::path defaultCacheDir();

}  // namespace eikon
