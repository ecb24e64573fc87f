// Where `eikon view`'s S key saves the view (docs/viewer.md "Saving the view"): into the folder
// --save-dir names, by default ~/Pictures/eikon (created when missing; the current folder only
// when HOME is unset), as SCENE-view-N.exr and SCENE-view-N.png with the first N for which
// neither file exists. The EXR's name is reserved by creating it exclusively (O_EXCL) before the
// pair is written over it, so two viewers saving at once, or a file made meanwhile, are never
// overwritten.
#pragma once

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <system_error>
#include <utility>

namespace eikon::cli {

/// $HOME/Pictures/eikon, or the current folder when HOME is unset or empty.
inline std::filesystem::path defaultViewSaveDir() {
  if (const char* home = std::getenv("HOME"); home && *home)
    return std::filesystem::path(home) / "Pictures" / "eikon";
  return ".";
}

/// The pair (EXR, PNG) the next save writes in `dir` (created when missing), the EXR reserved as
/// an empty file (the caller writes the pair over it, or removes it on failure); absolute paths.
/// Throws std::runtime_error with the reason when the folder cannot take the files.
inline std::pair<std::filesystem::path, std::filesystem::path> reserveViewSave(
    const std::filesystem::path& dir, const std::string& stem) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec)
    throw std::runtime_error("cannot create the folder '" + dir.string() + "': " + ec.message());
  const std::filesystem::path folder = std::filesystem::absolute(dir, ec);
  for (int k = 1; k <= 100000; ++k) {
    const std::string name = stem + "-view-" + std::to_string(k);
    const std::filesystem::path exr = folder / (name + ".exr"), png = folder / (name + ".png");
    if (std::filesystem::symlink_status(png, ec).type() != std::filesystem::file_type::not_found)
      continue;
    const int fd = ::open(exr.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
    if (fd < 0 && errno == EEXIST) continue;
    if (fd < 0)
      throw std::runtime_error("cannot create '" + exr.string() + "': " + std::strerror(errno));
    ::close(fd);
    return {exr, png};
  }
  throw std::runtime_error("'" + folder.string() + "' holds " + stem +
                           "-view-1 to -100000 already");
}

}  // namespace eikon::cli
