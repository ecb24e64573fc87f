// Reading a text input file (a scene, a material file, a GemCad .asc, fit data in CSV or YAML): the
// one reader every such file goes through, so that none of them reads an endless or enormous file.
// Before reading it checks that the path is a regular file after following links (not a
// directory, /dev/zero, a FIFO or a socket) of at most a stated size (kMaxTextFileBytes unless the
// caller gives a smaller cap); after reading, that the text holds no NUL byte (a scene followed by
// "\0garbage" was read up to the NUL and the rest ignored). A leading UTF-8 byte order mark (as
// Excel and Notepad write) is left out of the text it returns. Each refusal is one
// std::runtime_error "FILE: why" whose FILE is shownPath(path).
//
//   std::string text = eikon::readTextFile("scene.json", "a scene file");
//   // throws "scene.json: is not a regular file (a character device), expected a scene file"
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <system_error>

namespace eikon {

/// The largest text input file read: 64 MiB, far above any scene, material or data table.
constexpr std::uintmax_t kMaxTextFileBytes = 64u << 20;

/// `path` as a message shows it: itself when at most 200 bytes long, otherwise its first 160
/// bytes and "... (N bytes)". A NUL byte is shown as \x00 (an exception's what() would end at it);
/// other bytes are left for the message's printable() to escape (a shortened name stays far below
/// its cut).
std::string shownPath(const std::filesystem::path& path);

/// "a character device", "a block device", "a pipe", "a socket", else "not a plain file".
const char* fileTypeName(std::filesystem::file_type type);

/// The system's reason in a message's words: "file name too long", not "File name too long".
std::string errorReason(const std::error_code& ec);

/// True when `text` begins with a UTF-8 byte order mark (EF BB BF: Excel's "CSV UTF-8",
/// Notepad), which is no part of the text: left in, it stuck to the first word (a CSV header's, a
/// YAML key's), which a message then quoted looking exactly like the expected one.
inline bool startsWithByteOrderMark(std::string_view text) {
  return text.substr(0, 3) == "\xEF\xBB\xBF";
}

/// The bytes of the text file `path`, without a leading UTF-8 byte order mark (EF BB BF), which
/// the messages call `what` ("a scene file"). Throws
/// std::runtime_error "FILE: why" when the name holds a NUL byte, the file cannot be looked up or
/// opened (the system's reason: "no such file or directory", "file name too long"), is not a
/// regular file after following links, is larger than `max_bytes`, or holds a NUL byte (its
/// offset and line).
std::string readTextFile(const std::filesystem::path& path, const std::string& what,
                         std::uintmax_t max_bytes = kMaxTextFileBytes);

/// "FILE: holds a NUL byte at offset N (line L), expected WHAT (text)" when `text` holds one,
/// "" otherwise. For text that reached a parser without readTextFile.
std::string nulByteProblem(const std::string& text, const std::string& file,
                           const std::string& what);

}  // namespace eikon
