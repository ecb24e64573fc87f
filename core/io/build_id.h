// The GNU build id of the program (or shared object) this code was linked into: a digest the
// linker computes over the whole binary, so any change of the code gives another id. The caches
// of derived data whose bytes depend on eikon's code (core/volume/volume_cache.h: a voxelised
// volume is only valid for the voxeliser that made it) key their entries with it, so a rebuilt
// eikon never reads an entry written by another build, without a version number to remember to
// bump.
#pragma once

#include <string>

namespace eikon {

/// The build id as lower-case hex (40 digits for the linker's SHA-1 ids); empty when the binary
/// has none (linked with --build-id=none), and then callers cache nothing.
std::string codeBuildId();

}  // namespace eikon
