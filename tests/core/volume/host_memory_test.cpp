// Host memory is checked before voxelising: a volume the process cannot hold
// is refused with the numbers ("needs X GiB of host memory, Y available (LIMIT)") instead of
// ending in std::bad_alloc. Nothing here allocates the volumes it asks for.
#include "core/volume/host_memory.h"

#include <gtest/gtest.h>
#include <malloc.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fstream>
#include <string>

#include "core/scene/scene.h"
#include "core/volume/volume_set.h"

namespace eikon {
namespace {

Scene cubeScene(int resolution) {
  return parseScene(
      R"({"volume": {"bounds_min": [-12, -12, -12], "bounds_max": [12, 12, 12], "resolution": )" +
          std::to_string(resolution) + R"(},
                        "materials": {"glass": {"n": 1.5}},
                        "objects": [{"shape": "sphere", "radius": 5, "material": "glass"}]})",
      "memory.json");
}

double memTotal() {
  std::ifstream in("/proc/meminfo");
  std::string key;
  double kb = 0;
  while (in >> key >> kb)
    if (key == "MemTotal:") return kb * 1024.0;
  return 0;
}

// 1200³ voxels: the output volumes alone (3 index + medium + emission, 16 bytes each) are
// 1200³·80 bytes = 128.7 GiB.
TEST(HostMemory, HugeVolumeIsRefusedBeforeAllocating) {
  const Scene s = cubeScene(1200);
  const double need = voxelizeHostBytes(s, makeGrid(s.volume));
  EXPECT_GE(need, 1200.0 * 1200.0 * 1200.0 * 80.0);
  if (need < memTotal()) GTEST_SKIP() << "this machine could hold it";
  try {
    voxelize(s);
    ADD_FAILURE() << "voxelised 1200^3";
  } catch (const SceneError& e) {
    const std::string m = e.what();
    EXPECT_EQ(
        m.rfind("memory.json: /volume/resolution: voxelising 1200x1200x1200 voxels needs ", 0), 0u)
        << m;
    EXPECT_NE(m.find(" GiB of host memory, "), std::string::npos) << m;
    EXPECT_NE(m.find(" available ("), std::string::npos) << m;
  }
}

// In a child whose address space is capped 256 MiB above what it uses, the available memory is
// at most 256 MiB, limited by RLIMIT_AS, and a 128³ volume (≥ 128³·80 bytes = 160 MiB of output
// volumes, ≈ 470 MiB in all) is refused with a SceneError, not a std::bad_alloc.
// The child trims its heap before measuring, and the bound allows 32 MiB more: a free() between
// the two readings of /proc/self/statm may still hand heap pages back (the address space
// shrinks, so more is truly available), which the inherited heap's state decides, not the code.
TEST(HostMemory, LoweredAddressSpaceLimitIsRespected) {
  const Scene s = cubeScene(128);
  const pid_t pid = ::fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    ::malloc_trim(0);
    double pages = 0;
    std::ifstream("/proc/self/statm") >> pages;
    const double used = pages * double(::sysconf(_SC_PAGESIZE)), cap = 256.0 * (1 << 20);
    rlimit rl{rlim_t(used + cap), rlim_t(used + cap)};
    if (::setrlimit(RLIMIT_AS, &rl) != 0) ::_exit(10);
    const HostMemory m = availableHostMemory();
    if (m.limited_by != "RLIMIT_AS") ::_exit(11);
    if (!(double(m.available) <= cap + 32.0 * (1 << 20))) ::_exit(12);
    try {
      voxelize(s);
      ::_exit(13);
    } catch (const SceneError& e) {
      const std::string msg = e.what();
      ::_exit(msg.find("of host memory") != std::string::npos &&
                      msg.find("(RLIMIT_AS)") != std::string::npos
                  ? 0
                  : 14);
    } catch (const std::bad_alloc&) {
      ::_exit(15);
    }
  }
  int status = 0;
  ASSERT_EQ(::waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0)
      << "10 setrlimit, 11 not limited by RLIMIT_AS, 12 more than the cap, "
         "13 voxelised, 14 wrong message, 15 bad_alloc";
}

// Without a cap, a small volume still voxelises (the check does not refuse what fits).
TEST(HostMemory, SmallVolumeFits) {
  const HostMemory m = availableHostMemory();
  EXPECT_FALSE(m.limited_by.empty());
  EXPECT_NO_THROW(voxelize(cubeScene(16)));
}

}  // namespace
}  // namespace eikon
