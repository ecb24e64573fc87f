// A process-wide start-up timeline, to see where the time before the first dispatch goes
// (the aim: a small repeated render starts its first dispatch within 0.5 s of the process start).
// `eikon render --timings` (and `trace`), or EIKON_TIMINGS=1 in the environment of any program
// (the Python module, the benchmarks), prints one line per stage on stderr as the stage ends:
//
//   eikon: timing:    0.412 s  +0.301 s  voxelise
//
// the seconds since the process started (from /proc/self/stat, so the dynamic loader and static
// initialisation count too) and since the previous mark. Off by default: a mark then costs one
// relaxed atomic load. Lives on the ground floor (core/vk) so that the renderers and the apps can
// both mark; it knows nothing of what the stages are.
#pragma once

namespace eikon::timings {

/// Turn the printing on or off (on by default iff EIKON_TIMINGS=1).
void enable(bool on);
bool enabled();
/// Print "eikon: timing: <since start> s  +<since last mark> s  <stage>" when enabled.
void mark(const char* stage);
/// Seconds since the process started (since this library was loaded where /proc is missing).
double sinceProcessStart();

}  // namespace eikon::timings
