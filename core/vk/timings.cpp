#include "core/vk/timings.h"

#include <time.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <mutex>
#include <sstream>
#include <string>

namespace eikon::timings {
namespace {

const auto kLoaded = std::chrono::steady_clock::now();

/// The process's age when the library was loaded: CLOCK_BOOTTIME now minus the start time the
/// kernel keeps in /proc/self/stat (field 22, clock ticks since boot); 0 where either is missing
/// or the answer is implausible.
double ageAtLoad() {
  std::ifstream f("/proc/self/stat");
  std::string line;
  if (!std::getline(f, line)) return 0.0;
  const size_t paren = line.rfind(')');  // the command name may hold spaces and parentheses
  if (paren == std::string::npos) return 0.0;
  std::istringstream fields(line.substr(paren + 1));
  std::string tok;
  for (int field = 3; field <= 22 && fields >> tok; ++field)
    if (field == 22) {
      const long ticks_per_s = sysconf(_SC_CLK_TCK);
      timespec now{};
      if (ticks_per_s <= 0 || clock_gettime(CLOCK_BOOTTIME, &now) != 0) return 0.0;
      const double start = std::strtod(tok.c_str(), nullptr) / double(ticks_per_s);
      const double age = double(now.tv_sec) + 1e-9 * double(now.tv_nsec) - start;
      return age >= 0.0 && age < 60.0 ? age : 0.0;
    }
  return 0.0;
}

const double kAgeAtLoad = ageAtLoad();

std::atomic<bool>& flag() {
  static std::atomic<bool> on{[] {
    const char* e = std::getenv("EIKON_TIMINGS");
    return e && std::strcmp(e, "1") == 0;
  }()};
  return on;
}

std::mutex mutex;
double last = 0.0;

}  // namespace

void enable(bool on) { flag().store(on, std::memory_order_relaxed); }
bool enabled() { return flag().load(std::memory_order_relaxed); }

double sinceProcessStart() {
  return kAgeAtLoad +
         std::chrono::duration<double>(std::chrono::steady_clock::now() - kLoaded).count();
}

void mark(const char* stage) {
  if (!enabled()) return;
  std::lock_guard<std::mutex> lock(mutex);
  const double now = sinceProcessStart();
  std::fprintf(stderr, "eikon: timing: %8.3f s  +%.3f s  %s\n", now, now - last, stage);
  last = now;
}

}  // namespace eikon::timings
