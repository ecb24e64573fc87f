// Hostile scene and material input: duplicate JSON keys, material names used as paths,
// wavelength tables with non-positive wavelengths, directories given as files, and raw bytes in
// error messages. Every case is a SceneError of one line that names the file and the JSON path.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>

#include "core/scene/messages.h"
#include "core/scene/scene.h"
#include "tests/core/scene_support.h"

namespace eikon {
namespace {

namespace fs = std::filesystem;
constexpr const char* kOrigin = "input.json";

std::string errorOf(const std::string& text, const fs::path& origin = kOrigin) {
  return test::sceneErrorOf(text, origin);
}

#define EXPECT_INPUT_ERROR(text, json_path, phrase) \
  EXPECT_TRUE(test::isOneLineSceneError(errorOf(text), kOrigin, json_path, phrase))

using test::TempDir;

/// Sets an environment variable for the lifetime of the object.
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const std::string& value) : name_(name) {
    if (const char* old = std::getenv(name)) old_ = old, had_ = true;
    ::setenv(name, value.c_str(), 1);
  }
  ~ScopedEnv() {
    if (had_)
      ::setenv(name_, old_.c_str(), 1);
    else
      ::unsetenv(name_);
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
  EXPECT_INPUT_ERROR(
      R"({"materials": {)" + kGlass + R"(}, "objects": [], "objects": [)" + kSphere + "]}",
      "/objects", "duplicate key 'objects'");
  EXPECT_INPUT_ERROR(
      R"({"materials": {"glass": {"n": 1.5, "n": 1.6}}, "objects": [)" + kSphere + "]}",
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
  lib.write("dup.json",
            R"({"name": "dup", "n": 1.5, "attenuation_per_mm": 0.1, "attenuation_per_mm": 0.2})");
  ScopedEnv env("EIKON_MATERIALS_PATH", lib.path().string());
  const std::string m =
      errorOf(R"({"objects": [{"shape": "sphere", "radius": 3, "material": "dup"}]})");
  EXPECT_EQ(m.rfind((lib.path() / "dup.json").string() + ": /attenuation_per_mm: duplicate key", 0),
            0u)
      << m;
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
  for (const std::string& name : {std::string("../x"), abs, std::string("lib/../../x"),
                                  std::string(".."), std::string("a\\\\b"), std::string("")}) {
    EXPECT_INPUT_ERROR(
        R"({"objects": [{"shape": "sphere", "radius": 3, "material": ")" + name + R"("}]})",
        "/objects/0/material", "is not a plain name");
  }
  // The same material by its plain name from a library directory is found.
  ScopedEnv env2("EIKON_MATERIALS_PATH", root.path().string());
  EXPECT_NO_THROW(
      parseScene(R"({"objects": [{"shape": "sphere", "radius": 3, "material": "x"}]})", kOrigin));
}

// ------------------------------------------------------------------ wavelength tables

TEST(SceneInput, NonPositiveWavelengthsAreErrors) {
  for (const char* w : {"-500", "0"}) {
    EXPECT_INPUT_ERROR(
        R"({"materials": {"glass": {"n": 1.5, "attenuation_per_mm": {"wavelength_nm": [)" +
            std::string(w) + R"(, 600], "per_mm": [0.1, 0.2]}}}, "objects": [)" + kSphere + "]}",
        "/materials/glass/attenuation_per_mm/wavelength_nm/0", "must be > 0 nm");
    EXPECT_INPUT_ERROR(R"({"materials": {)" + kGlass + R"(}, "objects": [)" + kSphere +
                           R"(], "lights": [{"type": "point", "position": [0, 8, 0],
                           "spectrum": {"wavelength_nm": [)" +
                           std::string(w) + R"(, 500], "power": [1, 1]}}]})",
                       "/lights/0/spectrum/wavelength_nm/0", "must be > 0 nm");
  }
}

// ------------------------------------------------------------------ directories given as files

TEST(SceneInput, DirectoriesAreReportedAsDirectories) {
  TempDir d;
  fs::create_directory(d.path() / "scene.json");
  try {
    loadScene(d.path() / "scene.json");
    ADD_FAILURE() << "a directory loaded as a scene";
  } catch (const SceneError& e) {
    EXPECT_EQ(std::string(e.what()),
              (d.path() / "scene.json").string() + ": is a directory, expected a scene file");
  }
  fs::create_directory(d.path() / "env.exr");
  const std::string env = R"({"materials": {)" + kGlass + R"(}, "objects": [)" + kSphere +
                          R"(], "environment": {"type": "latlong", "file": "env.exr"}})";
  const std::string m = errorOf(env, d.path() / "s.json");
  EXPECT_EQ(m.rfind((d.path() / "s.json").string() + ": /environment/file: ", 0), 0u) << m;
  EXPECT_NE(m.find("env.exr: is a directory, expected an EXR image"), std::string::npos) << m;
  fs::create_directory(d.path() / "lib");
  fs::create_directory(d.path() / "lib" / "x.json");
  ScopedEnv lib("EIKON_MATERIALS_PATH", (d.path() / "lib").string());
  const std::string mm =
      errorOf(R"({"objects": [{"shape": "sphere", "radius": 3, "material": "x"}]})");
  EXPECT_EQ(mm,
            (d.path() / "lib" / "x.json").string() + ": is a directory, expected a material file");
}

// ------------------------------------------------------------------ bytes in messages

TEST(Printable, EscapesWhatIsNotPrintableText) {
  using namespace std::string_literals;
  EXPECT_EQ(printable("plain ASCII, backslash \\ kept"), "plain ASCII, backslash \\ kept");
  EXPECT_EQ(printable("λ = 587.6 nm, µm², ≥ 1, 🙂"),
            "λ = 587.6 nm, µm², ≥ 1, 🙂");  // valid UTF-8
  EXPECT_EQ(printable("a\0b"s), "a\\x00b");
  EXPECT_EQ(printable("line\nbreak\ttab\r\x7f"), "line\\x0abreak\\x09tab\\x0d\\x7f");
  EXPECT_EQ(printable("\xff\xfe"), "\\xff\\xfe");                    // never UTF-8
  EXPECT_EQ(printable("\xc0\xaf"), "\\xc0\\xaf");                    // overlong '/'
  EXPECT_EQ(printable("\xed\xa0\x80"), "\\xed\\xa0\\x80");           // a surrogate
  EXPECT_EQ(printable("\xc2\x85"), "\\xc2\\x85");                    // C1 control NEL
  EXPECT_EQ(printable("\xe2\x89"), "\\xe2\\x89");                    // truncated sequence
  EXPECT_EQ(printable("\xf4\x90\x80\x80"), "\\xf4\\x90\\x80\\x80");  // beyond U+10FFFF
}

TEST(Printable, TruncatesAtACharacterBoundary) {
  EXPECT_EQ(printable(std::string(1000, 'a'), 10), "aaaaaaaaaa... (1000 bytes)");
  // "λ" is 2 bytes: 5 of them fill 10 bytes, a 6th would not fit and is not split.
  EXPECT_EQ(printable("λλλλλλλ", 11), "λλλλλ... (14 bytes)");
  EXPECT_EQ(printable("\x01\x01\x01", 9), "\\x01\\x01... (3 bytes)");  // escapes are not split
  EXPECT_EQ(printable("short", 10), "short");
}

// Numbers in messages: the shortest text that reads back as the value. std::to_string printed
// 1e300 as 301 digits and 1e-7 as "0.000000".
TEST(FormatNumber, IsTheShortestRoundTrip) {
  EXPECT_EQ(formatNumber(1e300), "1e+300");
  EXPECT_EQ(formatNumber(-1e-7), "-1e-07");
  EXPECT_EQ(formatNumber(64.5), "64.5");
  EXPECT_EQ(formatNumber(100000.0), "100000");  // a whole number in full, not "1e+05"
  EXPECT_EQ(formatNumber(-65536.0), "-65536");
  EXPECT_EQ(formatNumber(1e15), "1e+15");
  EXPECT_EQ(formatNumber(0.1), "0.1");
  EXPECT_EQ(formatNumber(-0.0), "-0");
  EXPECT_EQ(formatNumber(1.0 / 3.0), "0.3333333333333333");
  EXPECT_EQ(formatNumber(4.9406564584124654e-324), "5e-324");
  EXPECT_EQ(formatNumber(std::numeric_limits<double>::infinity()), "inf");
  EXPECT_EQ(std::stod(formatNumber(1.5776540609934684)), 1.5776540609934684);
}

// A NUL inside a key or a name would cut the C string of the message (what(), printf): it is
// escaped, and what follows it is still in the message.
TEST(SceneInput, NulInANameIsEscaped) {
  const std::string m = errorOf(R"({"objects": [], "lamps\u0000after": 1})");
  EXPECT_NE(m.find("/lamps\\x00after: unknown key"), std::string::npos) << m;
  const std::string n =
      errorOf(R"({"objects": [{"shape": "sphere", "radius": 3, "material": "x\u0000y"}]})");
  EXPECT_NE(n.find("material name 'x\\x00y' is not a plain name"), std::string::npos) << n;
  const std::string k =
      errorOf(R"({"objects": [{"shape": "sphere\u0000", "radius": 3, "material": "g"}]})");
  EXPECT_NE(k.find("unknown shape 'sphere\\x00'"), std::string::npos) << k;
}

// Raw bytes of a binary file in the malformed-JSON message are escaped, and a long token is cut
// (a NUL byte is refused before parsing: NulBytesInJsonAreRefused).
TEST(SceneInput, BinaryBytesInMessagesAreEscapedAndShort) {
  using namespace std::string_literals;
  const std::string binary =
      "{\"objects\": [\"\x01\x02\xff\xfe\x80\x1b[31mred"s + std::string(100000, 'z');
  const std::string m = errorOf(binary);
  EXPECT_EQ(m.rfind(std::string(kOrigin) + ": malformed JSON", 0), 0u) << m;
  EXPECT_LT(m.size(), 600u);
  for (unsigned char c : m) EXPECT_TRUE(c >= 0x20 && c < 0x7f) << "byte " << int(c) << " in: " << m;
  // An unknown key of 100000 bytes is cut to an excerpt.
  const std::string key = errorOf(R"({"objects": [], ")" + std::string(100000, 'k') + R"(": 1})");
  EXPECT_LT(key.size(), 600u);
  EXPECT_NE(key.find("... (100000 bytes): unknown key"), std::string::npos) << key.substr(0, 300);
}

// ------------------------------------------------------------------ what a file is

// `eikon render /dev/zero` read without end (~300 MB/s), /dev/null read as an empty scene, and a
// library material linked to /dev/zero the same: scenes and material files are read only when they
// are regular files of at most 64 MiB (core/io/text_file.h).
TEST(SceneInput, OnlyRegularFilesAreRead) {
  try {
    loadScene("/dev/null");
    ADD_FAILURE() << "/dev/null loaded as a scene";
  } catch (const SceneError& e) {
    EXPECT_STREQ(e.what(),
                 "/dev/null: is not a regular file (a character device), expected a scene file");
  }
  TempDir d;
  fs::create_directory(d.path() / "lib");
  fs::create_symlink("/dev/null", d.path() / "lib" / "zz.json");
  ScopedEnv lib("EIKON_MATERIALS_PATH", (d.path() / "lib").string());
  EXPECT_EQ(errorOf(R"({"objects": [{"shape": "sphere", "radius": 3, "material": "zz"}]})"),
            (d.path() / "lib" / "zz.json").string() +
                ": is not a regular file (a character device), expected a material file");
}

// A valid scene followed by "\0garbage" rendered (nlohmann's parser stops at a NUL): a NUL byte in
// a scene or material file is refused with its offset and line.
TEST(SceneInput, NulBytesInJsonAreRefused) {
  using namespace std::string_literals;
  const std::string scene = R"({"materials": {)" + kGlass + R"(}, "objects": [)" + kSphere + "]}";
  EXPECT_EQ(errorOf(scene + "\n\0garbage {{{ \xff"s), "input.json: holds a NUL byte at offset " +
                                                          std::to_string(scene.size() + 1) +
                                                          " (line 2), expected JSON text (text)");
  TempDir d;
  const fs::path file = d.write("s.json", scene + "\0garbage"s);
  try {
    loadScene(file);
    ADD_FAILURE() << "a scene with a NUL loaded";
  } catch (const SceneError& e) {
    EXPECT_EQ(std::string(e.what()), file.string() + ": holds a NUL byte at offset " +
                                         std::to_string(scene.size()) +
                                         " (line 1), expected a scene file (text)");
  }
  fs::create_directory(d.path() / "lib");
  d.write("lib/nul.json", "{\"n\": 1.5}\0"s);
  ScopedEnv lib("EIKON_MATERIALS_PATH", (d.path() / "lib").string());
  EXPECT_NE(errorOf(R"({"objects": [{"shape": "sphere", "radius": 3, "material": "nul"}]})")
                .find("nul.json: holds a NUL byte at offset 10 (line 1)"),
            std::string::npos);
}

// A file name holding a NUL cut the message at it ("/objects/0/file: m"): it is refused as such.
TEST(SceneInput, NulInAFileNameIsRefused) {
  const std::string env = R"({"materials": {)" + kGlass + R"(}, "objects": [)" + kSphere +
                          R"(], "environment": {"type": "latlong", "file": "e\u0000.exr"}})";
  EXPECT_INPUT_ERROR(env, "/environment/file", "the file name 'e\\x00.exr' holds a NUL byte");
}

// Names too long for the system raised a bare "filesystem error: status: File name too long
// [...]" with neither scene nor JSON path, or lost the reason behind the name: the message names
// both, shortens the name and keeps the reason.
TEST(SceneInput, LongFileNamesKeepTheirReason) {
  const std::string material =
      errorOf(R"({"objects": [{"shape": "sphere", "radius": 3, "material": ")" +
              std::string(100000, 'x') + "\"}]}");
  EXPECT_TRUE(test::isOneLineSceneError(material, kOrigin, "/objects/0/material",
                                        "cannot look up the library material 'xxx"))
      << material.substr(0, 300);
  EXPECT_NE(material.find("... (100000 bytes)' as "), std::string::npos) << material;
  EXPECT_NE(material.find(": file name too long"), std::string::npos) << material;
  EXPECT_LT(material.size(), 600u);
  const std::string env = errorOf(R"({"materials": {)" + kGlass + R"(}, "objects": [)" + kSphere +
                                  R"(], "environment": {"type": "latlong", "file": ")" +
                                  std::string(5000, 'e') + ".exr\"}}");
  EXPECT_TRUE(test::isOneLineSceneError(env, kOrigin, "/environment/file",
                                        "... (5004 bytes): cannot open an EXR image: file name "
                                        "too long"))
      << env;
  EXPECT_LT(env.size(), 600u);
}

}  // namespace
}  // namespace eikon
