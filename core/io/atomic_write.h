// Writing output files so that readers and other writers never see a partial or mixed result:
// the one implementation of atomic file output in eikon (image writers, render outputs, caches).
//
// A file is written to a temporary "<name>.tmp-XXXXXXXX" in its target folder (created when
// missing) and renamed over the target, which POSIX makes atomic within one file system. A set of
// files that belong together (a render's EXR and its PNG preview) is written as a set:
//
//   1. every file to its own temporary; any failure (full disk, a codec error) removes the
//      temporaries and leaves every target as it was;
//   2. with an exclusive flock(2) on the lock file ".<stem>.lock" beside the first target
//      (".x.lock" for out/x.png and out/x.exr; OutputSetLock), each temporary is renamed over its
//      target, and the lock file is removed again.
//
// Two processes writing the same set at once therefore leave one process's complete set, never an
// EXR from one and a PNG from the other. The lock file exists only while a set is being renamed
// into place. Removing it safely takes a protocol (OutputSetLock): a writer opens it without
// following a symbolic link (a link planted there is refused, never followed to create a file at
// its target), locks it, and keeps the lock only if the path still names the file it locked (else
// it starts again); the holder unlinks it while still holding the lock, as its last act. A writer
// that waited on the unlinked file then finds it gone and starts again, so no two writers ever
// hold the lock of the file the path names.
//
//   eikon::writeFilesTogether({{"out/x.png", [&](const auto& tmp) { encodePng(tmp); }},
//                              {"out/x.exr", [&](const auto& tmp) { encodeExr(tmp); }}});
#pragma once

#include <filesystem>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

namespace eikon {

/// Writes one file's content to the path it is given (a temporary beside the target); throws on
/// failure, with the reason only: the writer reports "cannot write 'TARGET': reason".
using FileContent = std::function<void(const std::filesystem::path& tmp)>;

struct OutputFile {
  std::filesystem::path path;
  FileContent write;
};

/// Check that `path` can be created: it is not a folder, and its folder, or the nearest existing
/// folder above it when folders are missing (the writers create them), takes new files. Throws
/// std::runtime_error with a clear message otherwise, creating nothing. Call before long work so
/// that it fails early.
void checkWritable(const std::filesystem::path& path);

/// Write one file atomically (steps 1 and 2 above for a set of one, without a lock). Throws
/// std::runtime_error "cannot write 'PATH': why" (the reason from `write` when it threw); the
/// target is then unchanged.
void writeFileAtomically(const std::filesystem::path& path, const FileContent& write);

/// Write `bytes` to `path` atomically.
void writeBytesAtomically(const std::filesystem::path& path, std::string_view bytes);

/// The FileContent that writes `bytes` (for sets of in-memory files).
FileContent bytesWriter(std::string bytes);

/// Write the files as a set (see above): all of them replace their targets, or none does.
/// Throws like writeFileAtomically.
void writeFilesTogether(const std::vector<OutputFile>& files);

/// The lock file writeFilesTogether holds for a set whose first file is `first`.
std::filesystem::path lockPathFor(const std::filesystem::path& first);

/// The exclusive lock of the set whose first file is `first` (the protocol above), held from
/// construction to destruction, which removes the lock file. Throws std::runtime_error "cannot
/// write 'LOCK': why" for a lock file that is a symbolic link or not a regular file. A reader
/// that must see a set whole takes it too.
class OutputSetLock {
 public:
  explicit OutputSetLock(const std::filesystem::path& first);
  ~OutputSetLock();
  OutputSetLock(const OutputSetLock&) = delete;
  OutputSetLock& operator=(const OutputSetLock&) = delete;

 private:
  void release(bool remove);
  std::filesystem::path path_;
  int fd_ = -1;
};

}  // namespace eikon
