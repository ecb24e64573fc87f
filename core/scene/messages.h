// Text of user-facing messages. Error messages quote user input — file names, JSON keys and
// values, bytes of a malformed file — and that input may hold anything: control characters that
// break the one-line format, a NUL that cuts a C string (what(), printf) and so the message,
// bytes that are not UTF-8 (a terminal shows garbage, Python's str() of the message fails), or a
// megabyte-long token. Every message passes through printable() once before anyone sees it:
// SceneError escapes its message on construction, and the eikon command formats every error
// line with errorLine().
//
//   printable("a\0b\xff", 64)  → "a\x00b\xff" (as the four-character escapes)
//   printable(long_text, 80)   → the first ≤ 80 bytes, then "... (12345 bytes)"
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

namespace eikon {

/// `text` made safe to show on one line: printable ASCII and valid UTF-8 characters (other than
/// the C0/C1 control characters and DEL) pass through, every other byte becomes \xNN; longer than
/// `max_bytes` (after escaping), it is cut at a character boundary and "... (N bytes)" appended,
/// N the length of `text`. Backslashes are left alone, so text that is already printable (and
/// short enough) passes unchanged.
std::string printable(std::string_view text, size_t max_bytes = 4096);

/// A short excerpt of user input for a message: printable(text, 80).
inline std::string excerpt(std::string_view text) { return printable(text, 80); }

/// The one line the eikon command prints for an error: "eikon: error: <printable message>\n".
std::string errorLine(std::string_view message);

/// A number as a message shows it: the shortest text that reads back as `v` ("0.1", "64.5",
/// "1e+300", "-1e-07", "inf", "nan"; a whole number below 1e15 in full, "100000"), never
/// std::to_string's 300 digits of 1e300 nor its "0.000000" for 1e-7.
std::string formatNumber(double v);

}  // namespace eikon
