#include "core/io/text_file.h"

#include <algorithm>
#include <cerrno>
#include <fstream>
#include <stdexcept>
#include <system_error>

namespace eikon {

std::string errorReason(const std::error_code& ec) {
  std::string r = ec.message();
  if (!r.empty() && r[0] >= 'A' && r[0] <= 'Z' && !(r.size() > 1 && r[1] >= 'A' && r[1] <= 'Z'))
    r[0] = char(r[0] - 'A' + 'a');
  return r;
}

const char* fileTypeName(std::filesystem::file_type t) {
  using std::filesystem::file_type;
  switch (t) {
    case file_type::character:
      return "a character device";
    case file_type::block:
      return "a block device";
    case file_type::fifo:
      return "a pipe";
    case file_type::socket:
      return "a socket";
    default:
      return "not a plain file";
  }
}

namespace {

std::string mib(std::uintmax_t bytes) {
  if (bytes % (1u << 20) == 0) return std::to_string(bytes >> 20) + " MiB";
  return std::to_string(bytes) + " bytes";
}

}  // namespace

std::string shownPath(const std::filesystem::path& path) {
  const std::string& s = path.native();
  std::string shown = s.size() <= 200 ? s : s.substr(0, 160);
  // An exception's what() is a C string: a NUL would end the message there.
  for (size_t at = shown.find('\0'); at != std::string::npos; at = shown.find('\0', at + 4))
    shown.replace(at, 1, "\\x00");
  if (s.size() > 200) shown += "... (" + std::to_string(s.size()) + " bytes)";
  return shown;
}

std::string nulByteProblem(const std::string& text, const std::string& file,
                           const std::string& what) {
  const size_t at = text.find('\0');
  if (at == std::string::npos) return {};
  const auto line = 1 + std::count(text.begin(), text.begin() + std::ptrdiff_t(at), '\n');
  return file + ": holds a NUL byte at offset " + std::to_string(at) + " (line " +
         std::to_string(line) + "), expected " + what + " (text)";
}

std::string readTextFile(const std::filesystem::path& path, const std::string& what,
                         std::uintmax_t max_bytes) {
  namespace fs = std::filesystem;
  const std::string name = shownPath(path);
  auto refuse = [&](const std::string& why) { throw std::runtime_error(name + ": " + why); };
  if (path.native().find('\0') != std::string::npos)
    refuse("the file name holds a NUL byte, expected " + what);
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);  // follows links
  if (st.type() == fs::file_type::not_found)
    refuse("cannot open " + what + ": no such file or directory");
  if (ec) refuse("cannot open " + what + ": " + errorReason(ec));
  if (st.type() == fs::file_type::directory) refuse("is a directory, expected " + what);
  if (st.type() != fs::file_type::regular)
    refuse("is not a regular file (" + std::string(fileTypeName(st.type())) + "), expected " +
           what);
  const std::uintmax_t size = fs::file_size(path, ec);
  if (ec) refuse("cannot open " + what + ": " + errorReason(ec));
  const std::string too_large = "is larger than " + mib(max_bytes);
  if (size > max_bytes)
    refuse(too_large + " (" + std::to_string(size) + " bytes), expected " + what);
  std::ifstream in(path, std::ios::binary);
  if (!in)
    refuse("cannot open " + what + ": " +
           errorReason(std::error_code(errno, std::generic_category())));
  // Read to the end, but never more than max_bytes + 1: the file may have grown since its size
  // was taken.
  std::string text;
  text.reserve(size_t(size));
  char chunk[1 << 16];
  while (in.read(chunk, sizeof chunk) || in.gcount() > 0) {
    text.append(chunk, size_t(in.gcount()));
    if (text.size() > max_bytes) refuse(too_large + ", expected " + what);
  }
  if (in.bad()) refuse("cannot read " + what);
  const std::string nul = nulByteProblem(text, name, what);
  if (!nul.empty()) throw std::runtime_error(nul);
  if (startsWithByteOrderMark(text)) text.erase(0, 3);
  return text;
}

}  // namespace eikon
