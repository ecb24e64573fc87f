// How much host memory this process may still allocate, so that large volumes are refused with
// numbers before allocating instead of ending in std::bad_alloc (or the OOM killer) half-way.
// Device memory is checked separately (checkVolumeFits in core/render/view_renderer.h).
#pragma once

#include <cstdint>
#include <string>

namespace eikon {

struct HostMemory {
  uint64_t available = UINT64_MAX;  ///< bytes; UINT64_MAX if nothing could be read
  std::string limited_by;  ///< which limit gave `available` ("MemAvailable", "RLIMIT_AS", ...)
};

/// The least of: MemAvailable (/proc/meminfo); the soft RLIMIT_AS minus the address space in use
/// (/proc/self/statm); the soft RLIMIT_DATA minus the data segment in use (VmData); and the
/// memory limit minus the usage of this process's cgroup and its ancestors (v2: memory.max and
/// memory.current; v1: memory.limit_in_bytes and memory.usage_in_bytes).
HostMemory availableHostMemory();

/// "12.3 GiB" (or MiB below 1 GiB), for messages.
std::string formatBytes(double bytes);

}  // namespace eikon
