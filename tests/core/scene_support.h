// Helpers shared by the scene-parser tests (scene_test, scene_input_test, scene_limits_test): the
// error a scene text raises, the one-line "FILE: /json/path: ..." check, and a temporary folder.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>

#include "core/scene/scene.h"

namespace eikon::test {

/// The SceneError message that parsing `text` (as if read from `origin`) raises; a test failure
/// (and "") when the scene parses.
inline std::string sceneErrorOf(const std::string& text, const std::filesystem::path& origin) {
  try {
    parseScene(text, origin);
  } catch (const SceneError& e) {
    return e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "expected eikon::SceneError, got another exception: " << e.what();
    return {};
  }
  ADD_FAILURE() << "expected a SceneError, the scene parsed:\n" << text;
  return {};
}

/// `message` is one line that starts "ORIGIN: JSON_PATH: " and contains `phrase`.
inline ::testing::AssertionResult isOneLineSceneError(const std::string& message,
                                                      const std::string& origin,
                                                      const std::string& json_path,
                                                      const std::string& phrase) {
  if (message.rfind(origin + ": " + json_path + ": ", 0) != 0)
    return ::testing::AssertionFailure()
           << "does not start with '" << origin << ": " << json_path << ": ': " << message;
  if (message.find(phrase) == std::string::npos)
    return ::testing::AssertionFailure() << "lacks '" << phrase << "': " << message;
  if (message.find('\n') != std::string::npos)
    return ::testing::AssertionFailure() << "more than one line: " << message;
  return ::testing::AssertionSuccess();
}

/// A fresh folder under the system's temporary folder, removed with everything in it.
class TempDir {
 public:
  TempDir() {
    std::string tmpl = (std::filesystem::temp_directory_path() / "eikon_scene_XXXXXX").string();
    if (::mkdtemp(tmpl.data()) == nullptr) throw std::runtime_error("mkdtemp failed");
    dir_ = tmpl;
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(dir_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  std::filesystem::path write(const std::string& name, const std::string& text) const {
    std::ofstream(dir_ / name, std::ios::binary) << text;
    return dir_ / name;
  }
  const std::filesystem::path& path() const { return dir_; }

 private:
  std::filesystem::path dir_;
};

}  // namespace eikon::test
