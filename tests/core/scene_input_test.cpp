// Hostile scene and material input (issue 11): duplicate JSON keys, material names used as paths,
// wavelength tables with non-positive wavelengths, directories given as files, and raw bytes in
// error messages. Every case is a SceneError of one line that names the file and the JSON path.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "core/scene/scene.h"

namespace eikon {
namespace {

namespace fs = std::filesystem;
constexpr const char* kOrigin = "input.json";

std::string errorOf(const std::string& text, const fs::path& origin = kOrigin) {
  try {
    parseScene(text, origin);
  } catch (const SceneError& e) {
    return e.what();
  }
  ADD_FAILURE() << "the scene parsed:\n" << text;
  return {};
}

#define EXPECT_INPUT_ERROR(text, json_path, phrase)                                                    \
  do {                                                                                                 \
    const std::string m_ = errorOf(text);                                                              \
    EXPECT_EQ(m_.rfind(std::string(kOrigin) + ": " + (json_path) + ": ", 0), 0u) << m_;                \
    EXPECT_NE(m_.find(phrase), std::string::npos) << "lacks '" << (phrase) << "': " << m_;             \
    EXPECT_EQ(m_.find('\n'), std::string::npos) << m_;                                                 \
  } while (0)

class TempDir {
 public:
  TempDir() {
    std::string tmpl = (fs::temp_directory_path() / "eikon_input_test_XXXXXX").string();
    if (::mkdtemp(tmpl.data()) == nullptr) throw std::runtime_error("mkdtemp failed");
    dir_ = tmpl;
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  fs::path write(const std::string& name, const std::string& text) const {
    std::ofstream(dir_ / name, std::ios::binary) << text;
    return dir_ / name;
  }
  const fs::path& path() const { return dir_; }

 private:
  fs::path dir_;
};

/// Sets an environment variable for the lifetime of the object.
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const std::string& value) : name_(name) {
    if (const char* old = std::getenv(name)) old_ = old, had_ = true;
    ::setenv(name, value.c_str(), 1);
  }
  ~ScopedEnv() {
    if (had_) ::setenv(name_, old_.c_str(), 1);
    else ::unsetenv(name_);
  }

 private:
  const char* name_;
  std::string old_;
  bool had_ = false;
};

const std::string kGlass = R"("glass": {"n": 1.5})";
const std::string kSphere = R"({"shape": "sphere", "radius": 3, "material": "glass"})";

// ------------------------------------------------------------------ duplicate keys

TEST(SceneInput, DuplicateKeysAreErrors) {
  EXPECT_INPUT_ERROR(R"({"materials": {)" + kGlass + R"(}, "objects": [], "objects": [)" + kSphere + "]}", "/objects",
                     "duplicate key 'objects'");
  EXPECT_INPUT_ERROR(R"({"materials": {"glass": {"n": 1.5, "n": 1.6}}, "objects": [)" + kSphere + "]}",
                     "/materials/glass/n", "duplicate key 'n'");
  // In the second element of an array, after an element holding arrays (the path counts elements).
  EXPECT_INPUT_ERROR(R"({"materials": {)" + kGlass + R"(}, "objects": [
      {"shape": "planes", "planes": [[1, 0, 0, 1], [-1, 0, 0, 1], [0, 1, 0, 1], [0, -1, 0, 1], [0, 0, 1, 1], [0, 0, -1, 1]],
       "material": "glass"},
      {"shape": "sphere", "radius": 1, "center": [0, 0, 0], "radius": 2, "material": "glass"}]})",
                     "/objects/1/radius", "duplicate key 'radius'");
  // The same key in two different objects is fine.
  EXPECT_NO_THROW(parseScene(R"({"materials": {"a": {"n": 1.5}, "b": {"n": 1.6}}, "objects": [
      {"shape": "sphere", "radius": 1, "center": [-4, 0, 0], "material": "a"},
      {"shape": "sphere", "radius": 1, "center": [4, 0, 0], "material": "b"}]})",
                             kOrigin));
}

TEST(SceneInput, DuplicateKeyInAMaterialFile) {
  TempDir lib;
  lib.write("dup.json", R"({"name": "dup", "n": 1.5, "attenuation_per_mm": 0.1, "attenuation_per_mm": 0.2})");
  ScopedEnv env("EIKON_MATERIALS_PATH", lib.path().string());
  const std::string m = errorOf(R"({"objects": [{"shape": "sphere", "radius": 3, "material": "dup"}]})");
  EXPECT_EQ(m.rfind((lib.path() / "dup.json").string() + ": /attenuation_per_mm: duplicate key", 0), 0u) << m;
}

// ------------------------------------------------------------------ material names

// "../x" from a library directory reaches a JSON file outside it: the name is refused before any
// file is looked up (the file exists and is a valid material, so only the name check stops it).
TEST(SceneInput, MaterialNamesAreNotPaths) {
  TempDir root;
  fs::create_directory(root.path() / "lib");
  const fs::path outside = root.write("x.json", R"({"n": 1.7})");
  ScopedEnv env("EIKON_MATERIALS_PATH", (root.path() / "lib").string());
  const std::string abs = (root.path() / "x").string();  // + ".json" names the file above
  for (const std::string& name : {std::string("../x"), abs, std::string("lib/../../x"), std::string(".."),
                                   std::string("a\\\\b"), std::string("")}) {
    EXPECT_INPUT_ERROR(R"({"objects": [{"shape": "sphere", "radius": 3, "material": ")" + name + R"("}]})",
                       "/objects/0/material", "is not a plain name");
  }
  // The same material by its plain name from a library directory is found.
  ScopedEnv env2("EIKON_MATERIALS_PATH", root.path().string());
  EXPECT_NO_THROW(parseScene(R"({"objects": [{"shape": "sphere", "radius": 3, "material": "x"}]})", kOrigin));
}

}  // namespace
}  // namespace eikon
