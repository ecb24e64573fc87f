// core/io/text_file.h: text inputs (scenes, material files, fit data) are read only when they are
// regular files of bounded size without NUL bytes. `eikon render /dev/zero` used to read without
// end (~300 MB/s), and a scene followed by "\0garbage" was read up to the NUL and rendered.
#include "core/io/text_file.h"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <stdexcept>
#include <string>

#include "tests/core/file_support.h"

namespace eikon {
namespace {

namespace fs = std::filesystem;
using namespace std::string_literals;

/// The message readTextFile throws for `path` (a test failure, and "", when it reads the file).
std::string refusal(const fs::path& path, std::uintmax_t max_bytes = kMaxTextFileBytes) {
  try {
    readTextFile(path, "a scene file", max_bytes);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  ADD_FAILURE() << "read " << path;
  return {};
}

class TextFile : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string tmpl = (fs::temp_directory_path() / "eikon_text_file_XXXXXX").string();
    ASSERT_NE(::mkdtemp(tmpl.data()), nullptr);
    dir_ = tmpl;
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  fs::path dir_;
};

TEST_F(TextFile, ReadsARegularFileWhole) {
  test::put(dir_ / "s.json", "{\"objects\": []}\n");
  EXPECT_EQ(readTextFile(dir_ / "s.json", "a scene file"), "{\"objects\": []}\n");
  fs::create_symlink(dir_ / "s.json", dir_ / "link.json");  // links are followed
  EXPECT_EQ(readTextFile(dir_ / "link.json", "a scene file"), "{\"objects\": []}\n");
}

// /dev/null read as an empty file, /dev/zero (and a link to it) without end: neither is opened.
TEST_F(TextFile, DevicesPipesAndDirectoriesAreRefused) {
  EXPECT_EQ(refusal("/dev/zero"),
            "/dev/zero: is not a regular file (a character device), expected a scene file");
  EXPECT_EQ(refusal("/dev/null"),
            "/dev/null: is not a regular file (a character device), expected a scene file");
  fs::create_symlink("/dev/zero", dir_ / "z.csv");
  EXPECT_EQ(refusal(dir_ / "z.csv"), (dir_ / "z.csv").string() +
                                         ": is not a regular file (a character device), "
                                         "expected a scene file");
  ASSERT_EQ(::mkfifo((dir_ / "fifo").c_str(), 0600), 0);  // opening it would wait for a writer
  EXPECT_NE(refusal(dir_ / "fifo").find("fifo: is not a regular file (a pipe)"), std::string::npos);
  fs::create_directory(dir_ / "d.json");
  EXPECT_EQ(refusal(dir_ / "d.json"),
            (dir_ / "d.json").string() + ": is a directory, expected a scene file");
  EXPECT_EQ(
      refusal(dir_ / "missing.json"),
      (dir_ / "missing.json").string() + ": cannot open a scene file: no such file or directory");
}

TEST_F(TextFile, SizeIsCapped) {
  // A sparse file one byte over the 64 MiB cap: refused from its size, before reading.
  test::put(dir_ / "big.json", "");
  fs::resize_file(dir_ / "big.json", kMaxTextFileBytes + 1);
  EXPECT_EQ(refusal(dir_ / "big.json"), (dir_ / "big.json").string() +
                                            ": is larger than 64 MiB (67108865 bytes), expected "
                                            "a scene file");
  test::put(dir_ / "small.json", "12345");
  EXPECT_EQ(refusal(dir_ / "small.json", 4), (dir_ / "small.json").string() +
                                                 ": is larger than 4 bytes (5 bytes), expected a " +
                                                 "scene file");
  EXPECT_EQ(readTextFile(dir_ / "small.json", "a scene file", 5), "12345");
}

TEST_F(TextFile, NulBytesAreRefusedWithTheirOffsetAndLine) {
  test::put(dir_ / "nul.json", "{\"objects\": []}\n\0garbage {{{ \xff"s);
  EXPECT_EQ(refusal(dir_ / "nul.json"),
            (dir_ / "nul.json").string() +
                ": holds a NUL byte at offset 16 (line 2), expected a scene file (text)");
  EXPECT_EQ(nulByteProblem("ab\n\ncd\0"s, "f.json", "JSON text"),
            "f.json: holds a NUL byte at offset 6 (line 3), expected JSON text (text)");
  EXPECT_EQ(nulByteProblem("no nul", "f.json", "JSON text"), "");
}

// A UTF-8 byte order mark (Excel's "CSV UTF-8", Notepad) is no part of the text: left in, it stuck
// to the first word of a CSV header, which a message quoted looking just like the expected word.
// Only a leading one is left out; one further on is text.
TEST_F(TextFile, LeadingByteOrderMarkIsLeftOut) {
  test::put(dir_ / "bom.csv", "\xEF\xBB\xBFwavelength_nm,n\n");
  EXPECT_EQ(readTextFile(dir_ / "bom.csv", "a data file"), "wavelength_nm,n\n");
  test::put(dir_ / "only.json", "\xEF\xBB\xBF");
  EXPECT_EQ(readTextFile(dir_ / "only.json", "a scene file"), "");
  test::put(dir_ / "inner.csv", "a\xEF\xBB\xBF\n");
  EXPECT_EQ(readTextFile(dir_ / "inner.csv", "a data file"), "a\xEF\xBB\xBF\n");
  test::put(dir_ / "part.csv", "\xEF\xBBx");  // not a whole mark
  EXPECT_EQ(readTextFile(dir_ / "part.csv", "a data file"), "\xEF\xBBx");
}

// A NUL in the name is shown as \x00 (what() is a C string: the message stopped at it), a name
// too long for the system is shortened and keeps the reason.
TEST_F(TextFile, OddNamesAreShownWhole) {
  EXPECT_EQ(refusal("m\0.json"s),
            "m\\x00.json: the file name holds a NUL byte, expected a scene file");
  const fs::path long_name = dir_ / (std::string(5000, 'x') + ".json");
  const std::string m = refusal(long_name);
  EXPECT_LT(m.size(), 300u) << m;
  EXPECT_NE(m.find("... (" + std::to_string(long_name.native().size()) + " bytes)"),
            std::string::npos)
      << m;
  EXPECT_NE(m.find(": cannot open a scene file: file name too long"), std::string::npos) << m;
  EXPECT_EQ(shownPath("short/name.json"), "short/name.json");
  EXPECT_EQ(shownPath(std::string(201, 'a')), std::string(160, 'a') + "... (201 bytes)");
}

}  // namespace
}  // namespace eikon
