#include "core/scene/messages.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>

namespace eikon {
namespace {

/// Length of the valid UTF-8 sequence at s[i] that encodes a printable character (not a C1
/// control), or 0 (RFC 3629: no overlong forms, no surrogates, at most U+10FFFF).
size_t printableUtf8(std::string_view s, size_t i) {
  const auto b = [&](size_t k) { return static_cast<unsigned char>(s[k]); };
  const unsigned char c = b(i);
  size_t n;
  char32_t cp;
  if (c >= 0xC2 && c <= 0xDF)
    n = 2, cp = c & 0x1F;
  else if (c >= 0xE0 && c <= 0xEF)
    n = 3, cp = c & 0x0F;
  else if (c >= 0xF0 && c <= 0xF4)
    n = 4, cp = c & 0x07;
  else
    return 0;
  if (i + n > s.size()) return 0;
  for (size_t k = 1; k < n; ++k) {
    if ((b(i + k) & 0xC0) != 0x80) return 0;
    cp = (cp << 6) | (b(i + k) & 0x3F);
  }
  // Overlong forms and code points beyond Unicode, surrogates, C1 controls.
  if ((n == 3 && cp < 0x800) || (n == 4 && (cp < 0x10000 || cp > 0x10FFFF))) return 0;
  if (cp >= 0xD800 && cp <= 0xDFFF) return 0;
  if (cp >= 0x80 && cp <= 0x9F) return 0;
  return n;
}

}  // namespace

std::string printable(std::string_view text, size_t max_bytes) {
  std::string out;
  out.reserve(std::min(text.size(), max_bytes) + 16);
  for (size_t i = 0; i < text.size();) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    std::string piece;
    size_t used = 1;
    if (c >= 0x20 && c < 0x7F) {
      piece.assign(1, char(c));
    } else if (size_t n = c >= 0x80 ? printableUtf8(text, i) : 0) {
      piece.assign(text.substr(i, n));
      used = n;
    } else {
      char esc[5];
      std::snprintf(esc, sizeof esc, "\\x%02x", c);
      piece = esc;
    }
    if (out.size() + piece.size() > max_bytes) {
      out += "... (" + std::to_string(text.size()) + " bytes)";
      return out;
    }
    out += piece;
    i += used;
  }
  return out;
}

std::string errorLine(std::string_view message) {
  return "eikon: error: " + printable(message) + "\n";
}

std::string formatNumber(double v) {
  char buf[32];  // the shortest round trip of a double takes at most 24 characters
  // A whole number below 1e15 in full ("100000", not the shorter "1e+05"), as a limit reads.
  const bool whole = std::isfinite(v) && std::abs(v) < 1e15 && v == std::trunc(v);
  const std::to_chars_result r =
      whole ? std::to_chars(buf, buf + sizeof buf, v, std::chars_format::fixed)
            : std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

}  // namespace eikon
