#include "core/io/atomic_write.h"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <optional>
#include <random>
#include <stdexcept>
#include <string>

#include "core/io/text_file.h"

namespace eikon {
namespace {

std::runtime_error writeError(const std::filesystem::path& path, const std::string& why) {
  return std::runtime_error("cannot write '" + path.string() + "': " + why);
}

/// Create a new empty file "<path>.tmp-XXXXXXXX" (O_EXCL, mode 0666 less the umask, as the
/// target would get) and return its name.
std::filesystem::path createTemporary(const std::filesystem::path& path) {
  std::random_device rd;
  for (int attempt = 0; attempt < 100; ++attempt) {
    char suffix[32];
    std::snprintf(suffix, sizeof suffix, ".tmp-%08x", rd());
    std::filesystem::path tmp(path.string() + suffix);
    const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd >= 0) {
      ::close(fd);
      return tmp;
    }
    if (errno != EEXIST)
      throw writeError(path,
                       std::string("cannot create a file beside it: ") + std::strerror(errno));
  }
  throw writeError(path, "cannot create a temporary file beside it");
}

/// Create the missing folders above `path`, appending each one made to `created` (outermost
/// first) so that a failed write can remove them again: no partial output, not even a folder.
void createParentFolders(const std::filesystem::path& path,
                         std::vector<std::filesystem::path>& created) {
  std::vector<std::filesystem::path> missing;
  std::error_code ec;
  for (auto d = path.parent_path(); !d.empty() && !std::filesystem::exists(d, ec);
       d = d.parent_path()) {
    missing.push_back(d);
    if (d == d.parent_path()) break;
  }
  for (auto it = missing.rbegin(); it != missing.rend(); ++it) {
    if (!std::filesystem::create_directory(*it, ec) && !std::filesystem::is_directory(*it))
      throw writeError(path, "cannot create folder '" + it->string() +
                                 "': " + (ec ? ec.message() : std::string("a file stands there")));
    created.push_back(*it);
  }
}

}  // namespace

/// The file an output path names: a symbolic link's final target (so the link stays and shows
/// the new file), which must be a regular file or not exist yet. A device, pipe or socket there
/// is refused: the rename over it would replace it with a file (`-o /dev/null` as root did).
std::filesystem::path outputTarget(const std::filesystem::path& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::path p = path;
  if (fs::is_symlink(fs::symlink_status(p, ec))) {
    p = fs::weakly_canonical(p, ec);  // follows every link, to a file that may not exist yet
    if (ec) throw writeError(path, "cannot follow the symbolic link: " + errorReason(ec));
  }
  const fs::file_type t = fs::status(p, ec).type();
  if (t == fs::file_type::not_found || t == fs::file_type::regular) return p;
  if (t == fs::file_type::directory) throw writeError(path, "it is a directory");
  throw writeError(path, std::string("it is ") + fileTypeName(t) +
                             ", not a regular file: eikon writes a file beside it and renames it "
                             "over the target, which would replace it");
}

void checkWritable(const std::filesystem::path& target) {
  std::error_code ec;
  const std::filesystem::path path = outputTarget(target);
  // Missing folders are created when writing; here the nearest existing one must take new entries.
  std::filesystem::path dir = path.parent_path();
  while (!dir.empty() && !std::filesystem::exists(dir, ec))
    dir = dir.parent_path();  // "a/b" → "a" → ""
  if (dir.empty()) dir = ".";
  if (!std::filesystem::is_directory(dir, ec))
    throw writeError(path, "'" + dir.string() + "' is not a folder");
  if (::access(dir.c_str(), W_OK) != 0)
    throw writeError(path, "folder '" + dir.string() + "' is not writable");
  // access() says yes to root everywhere; creating a probe file is the real test.
  std::filesystem::path probe;
  try {
    probe = createTemporary(dir / path.filename());
  } catch (const std::exception&) {
    throw writeError(path, "cannot create files in '" + dir.string() + "'");
  }
  std::filesystem::remove(probe, ec);
}

std::filesystem::path lockPathFor(const std::filesystem::path& first) {
  return first.parent_path() / ("." + first.stem().string() + ".lock");
}

// The protocol (atomic_write.h): open without following a link, lock, and keep the lock only if
// the path still names the file locked. A waiter that wakes on a file its holder has unlinked (or
// that was replaced meanwhile) starts again on whatever the path names now. Only a process that
// holds the lock on the file the path names unlinks it, and it does so before it unlocks, as its
// last act under the lock; so no two processes ever hold a lock on the file the path names.
OutputSetLock::OutputSetLock(const std::filesystem::path& first) : path_(lockPathFor(first)) {
  for (int attempt = 0; attempt < 10000; ++attempt) {
    fd_ = ::open(path_.c_str(), O_RDWR | O_CREAT | O_NOFOLLOW | O_CLOEXEC, 0666);
    if (fd_ < 0 && errno == ELOOP)
      throw writeError(path_,
                       "the lock file is a symbolic link; eikon opens its lock file only "
                       "as a plain file (remove the link)");
    if (fd_ < 0)
      throw writeError(path_, std::string("cannot open the lock file: ") + std::strerror(errno));
    struct stat held {};
    if (::fstat(fd_, &held) != 0 || !S_ISREG(held.st_mode)) {
      release(false);
      throw writeError(path_, "the lock file is not a regular file");
    }
    while (::flock(fd_, LOCK_EX) != 0) {
      if (errno == EINTR) continue;
      const int err = errno;
      release(false);
      throw writeError(path_, std::string("cannot lock it: ") + std::strerror(err));
    }
    struct stat named {};
    if (::lstat(path_.c_str(), &named) == 0 && named.st_dev == held.st_dev &&
        named.st_ino == held.st_ino)
      return;        // locked, and it is the lock file the path names: held
    release(false);  // unlinked or replaced while this process waited: start again
  }
  throw writeError(path_, "cannot lock it: the lock file keeps being replaced");
}

OutputSetLock::~OutputSetLock() { release(true); }

void OutputSetLock::release(bool remove) {
  if (fd_ < 0) return;
  if (remove) ::unlink(path_.c_str());  // still holding the lock: see the protocol above
  ::flock(fd_, LOCK_UN);
  ::close(fd_);
  fd_ = -1;
}

void writeFilesTogether(const std::vector<OutputFile>& outputs) {
  if (outputs.empty()) return;
  std::vector<OutputFile> files = outputs;  // each at the file it names (outputTarget)
  for (OutputFile& f : files) f.path = outputTarget(f.path);
  std::vector<std::filesystem::path> tmps, created;
  auto removeTemporaries = [&] {
    std::error_code ec;
    for (const auto& t : tmps) std::filesystem::remove(t, ec);
    for (auto it = created.rbegin(); it != created.rend(); ++it)
      std::filesystem::remove(*it, ec);  // only if still empty
  };
  try {
    for (const OutputFile& f : files) {
      if (std::filesystem::is_directory(f.path)) throw writeError(f.path, "it is a directory");
      createParentFolders(f.path, created);
      tmps.push_back(createTemporary(f.path));
      try {
        f.write(tmps.back());
      } catch (const std::exception& e) {
        throw writeError(f.path, e.what());
      }
    }
    // One file needs no lock: its rename is atomic by itself.
    std::optional<OutputSetLock> lock;
    if (files.size() > 1) lock.emplace(files.front().path);
    // Under the lock: a target that became a folder since would fail its rename after earlier
    // renames had replaced their targets; refuse before replacing anything.
    for (const OutputFile& f : files)
      if (std::filesystem::is_directory(f.path)) throw writeError(f.path, "it is a directory");
    for (size_t i = 0; i < files.size(); ++i) {
      std::error_code ec;
      std::filesystem::rename(tmps[i], files[i].path, ec);
      if (ec) throw writeError(files[i].path, ec.message());
    }
  } catch (const std::filesystem::filesystem_error& e) {
    removeTemporaries();
    throw writeError(e.path1().empty() ? files.front().path : e.path1(), e.code().message());
  } catch (...) {
    removeTemporaries();
    throw;
  }
}

void writeFileAtomically(const std::filesystem::path& path, const FileContent& write) {
  writeFilesTogether({{path, write}});
}

FileContent bytesWriter(std::string bytes) {
  return [bytes = std::move(bytes)](const std::filesystem::path& tmp) {
    FILE* f = std::fopen(tmp.c_str(), "wb");
    if (!f) throw std::runtime_error(std::strerror(errno));
    const bool ok = std::fwrite(bytes.data(), 1, bytes.size(), f) == bytes.size();
    const int err = errno;
    if (std::fclose(f) != 0 || !ok) throw std::runtime_error(std::strerror(ok ? errno : err));
  };
}

void writeBytesAtomically(const std::filesystem::path& path, std::string_view bytes) {
  writeFileAtomically(path, bytesWriter(std::string(bytes)));
}

}  // namespace eikon
