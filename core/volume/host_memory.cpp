#include "core/volume/host_memory.h"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace eikon {
namespace {

/// The number after `key` in a "Key:   123 kB" file (bytes), or -1.
double statusField(const char* file, const std::string& key) {
  std::ifstream in(file);
  std::string line;
  while (std::getline(in, line))
    if (line.rfind(key, 0) == 0) {
      std::istringstream s(line.substr(key.size()));
      double kb = -1;
      s >> kb;
      return kb >= 0 ? kb * 1024.0 : -1;
    }
  return -1;
}

/// A cgroup control file holding a number of bytes ("max" or unreadable: -1).
double cgroupNumber(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::string v;
  if (!(in >> v) || v == "max") return -1;
  try {
    return std::stod(v);
  } catch (...) {
    return -1;
  }
}

void consider(HostMemory& m, double available, const std::string& what) {
  if (available < 0) available = 0;
  if (available < double(m.available)) {
    m.available = uint64_t(available);
    m.limited_by = what;
  }
}

void considerCgroups(HostMemory& m) {
  namespace fs = std::filesystem;
  std::ifstream in("/proc/self/cgroup");
  std::string line;
  while (std::getline(in, line)) {
    // "0::/path" (v2) or "4:memory:/path" (v1).
    const size_t a = line.find(':'), b = line.find(':', a + 1);
    if (a == std::string::npos || b == std::string::npos) continue;
    const std::string controllers = line.substr(a + 1, b - a - 1);
    const fs::path rel = fs::path(line.substr(b + 1)).relative_path();
    const bool v2 = controllers.empty();
    if (!v2 && controllers.find("memory") == std::string::npos) continue;
    const fs::path root = v2 ? fs::path("/sys/fs/cgroup") : fs::path("/sys/fs/cgroup/memory");
    const char* limit_file = v2 ? "memory.max" : "memory.limit_in_bytes";
    const char* usage_file = v2 ? "memory.current" : "memory.usage_in_bytes";
    // The group and its ancestors (each limit applies); in a cgroup namespace the group may be
    // mounted as the root itself.
    for (fs::path dir = rel;; dir = dir.parent_path()) {
      const fs::path d = root / dir;
      const double limit = cgroupNumber(d / limit_file);
      if (limit > 0 && limit < 1e18) {  // v1 writes ~2^63 for "no limit"
        const double usage = cgroupNumber(d / usage_file);
        consider(m, limit - std::max(usage, 0.0),
                 std::string("cgroup ") + (d / limit_file).string());
      }
      if (dir.empty()) break;
    }
  }
}

}  // namespace

HostMemory availableHostMemory() {
  HostMemory m;
  const double avail = statusField("/proc/meminfo", "MemAvailable:");
  if (avail >= 0) consider(m, avail, "MemAvailable");
  rlimit rl{};
  if (::getrlimit(RLIMIT_AS, &rl) == 0 && rl.rlim_cur != RLIM_INFINITY) {
    double used = 0;
    std::ifstream statm("/proc/self/statm");
    if (statm >> used) used *= double(::sysconf(_SC_PAGESIZE));
    consider(m, double(rl.rlim_cur) - used, "RLIMIT_AS");
  }
  if (::getrlimit(RLIMIT_DATA, &rl) == 0 && rl.rlim_cur != RLIM_INFINITY) {
    const double used = statusField("/proc/self/status", "VmData:");
    consider(m, double(rl.rlim_cur) - std::max(used, 0.0), "RLIMIT_DATA");
  }
  considerCgroups(m);
  return m;
}

std::string formatBytes(double bytes) {
  char s[32];
  if (bytes >= double(1ull << 30))
    std::snprintf(s, sizeof s, "%.1f GiB", bytes / double(1ull << 30));
  else
    std::snprintf(s, sizeof s, "%.0f MiB", bytes / double(1ull << 20));
  return s;
}

}  // namespace eikon
