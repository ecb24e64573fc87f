#include "core/io/cache_dir.h"

#include <cstdlib>

namespace eikon {

std::filesystem::path defaultCacheDir() {
  if (const char* d = std::getenv("EIKON_CACHE_DIR"); d && *d) return d;
  if (const char* d = std::getenv("XDG_CACHE_HOME"); d && *d)
    return std::filesystem::path(d) / "eikon";
  if (const char* d = std::getenv("HOME"); d && *d)
    return std::filesystem::path(d) / ".cache" / "eikon";
  return {};
}

}  // namespace eikon
