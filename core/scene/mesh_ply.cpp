// The PLY reader (core/scene/mesh_readers.h): the header is read first and every element count
// checked against the bytes after it; then the elements in their order, each property read or
// skipped by its type's size, every list's count checked against the bytes left before it is
// read. Nothing is allocated for what a count declares beyond the vertices (at most
// kMaxMeshVertices) and the faces' corners (bounded by kMaxMeshTriangles).
#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/scene/mesh_reader_support.h"
#include "core/scene/mesh_readers.h"
#include "core/scene/messages.h"

namespace eikon {
namespace {

using mesh_io::refuse;
using mesh_io::Where;

enum class Scalar { i8, u8, i16, u16, i32, u32, f32, f64, none };

struct ScalarInfo {
  const char* names[2];
  Scalar type;
  size_t bytes;
  bool integer;
  double lo, hi;
};

constexpr ScalarInfo kScalars[] = {
    {{"char", "int8"}, Scalar::i8, 1, true, -128.0, 127.0},
    {{"uchar", "uint8"}, Scalar::u8, 1, true, 0.0, 255.0},
    {{"short", "int16"}, Scalar::i16, 2, true, -32768.0, 32767.0},
    {{"ushort", "uint16"}, Scalar::u16, 2, true, 0.0, 65535.0},
    {{"int", "int32"}, Scalar::i32, 4, true, -2147483648.0, 2147483647.0},
    {{"uint", "uint32"}, Scalar::u32, 4, true, 0.0, 4294967295.0},
    {{"float", "float32"}, Scalar::f32, 4, false, 0.0, 0.0},
    {{"double", "float64"}, Scalar::f64, 8, false, 0.0, 0.0},
};

const ScalarInfo& info(Scalar t) { return kScalars[size_t(t)]; }

Scalar scalarNamed(std::string_view n) {
  for (const ScalarInfo& s : kScalars)
    if (n == s.names[0] || n == s.names[1]) return s.type;
  return Scalar::none;
}

struct Property {
  std::string name;
  bool list = false;
  Scalar count = Scalar::none, type = Scalar::none;  ///< list: count and item types
};

struct Element {
  std::string name;
  uint64_t count = 0;
  size_t line = 0;
  std::vector<Property> props;
  uint64_t least_bytes = 0;  ///< least bytes one takes (binary: its scalars; ASCII: 2 a value)
};

enum class Format { ascii, little, big };

struct Header {
  Format format = Format::ascii;
  std::vector<Element> elements;
  size_t bytes = 0;  ///< the header's length, end_header's line included
  size_t lines = 0;  ///< its lines
};

/// The words of one header line (the header is at most kMaxPlyHeaderBytes long).
std::vector<std::string_view> headerWords(std::string_view line) {
  std::vector<std::string_view> w;
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r')) ++i;
    const size_t b = i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t' && line[i] != '\r') ++i;
    if (i > b) w.push_back(line.substr(b, i - b));
  }
  return w;
}

/// One `property` line of the header, added to the last element.
void headerProperty(const std::vector<std::string_view>& w, Header& h, const std::string& name,
                    const Where& at) {
  if (h.elements.empty()) refuse(name, at, "a property before any element");
  Property p;
  const bool list = w.size() > 1 && w[1] == "list";
  if (w.size() != (list ? 5u : 3u))
    refuse(name, at,
           "expected 'property TYPE NAME' or 'property list COUNT_TYPE TYPE NAME', got '" +
               excerpt(w.size() > 1 ? w[1] : "") + "...' with " + std::to_string(w.size()) +
               " words");
  p.list = list;
  for (size_t k = 1 + list; k + 1 < w.size(); ++k) {
    const Scalar t = scalarNamed(w[k]);
    if (t == Scalar::none) refuse(name, at, "unknown property type '" + excerpt(w[k]) + "'");
    (k == 2 && list ? p.count : p.type) = t;
  }
  if (list && !info(p.count).integer)
    refuse(name, at, "a list's count type must be an integer type, got '" + excerpt(w[2]) + "'");
  p.name = std::string(w.back());
  Element& e = h.elements.back();
  e.least_bytes += h.format == Format::ascii ? 2 : info(list ? p.count : p.type).bytes;
  e.props.push_back(std::move(p));
}

/// The header: its format, its elements and their properties, and its length.
Header plyHeader(std::string_view s, const std::string& name) {
  if (s.substr(0, 4) != "ply\n" && s.substr(0, 5) != "ply\r\n")
    throw std::invalid_argument(name + ": is not a PLY file (its first line is not 'ply')");
  if (s.substr(0, kMaxPlyHeaderBytes).find("\nend_header") == std::string_view::npos)
    throw std::invalid_argument(name + ": the PLY header has no end_header line within its first " +
                                std::to_string(kMaxPlyHeaderBytes >> 10) + " KiB");
  Header h;
  bool format = false, ended = false;
  size_t pos = 0;
  while (pos < s.size() && pos < kMaxPlyHeaderBytes && !ended) {
    const size_t eol = std::min(s.find('\n', pos), s.size());
    const std::vector<std::string_view> w = headerWords(s.substr(pos, eol - pos));
    pos = eol + 1;
    const Where at{true, ++h.lines};
    if (h.lines == 1 || w.empty() || w[0] == "comment" || w[0] == "obj_info") continue;
    if (w[0] == "end_header") {
      ended = true;
    } else if (w[0] == "format") {
      if (format || !h.elements.empty())
        refuse(name, at, "a second format line, or one after an element");
      format = true;
      const std::string_view f = w.size() > 1 ? w[1] : "";
      if (f == "binary_little_endian")
        h.format = Format::little;
      else if (f == "binary_big_endian")
        h.format = Format::big;
      else if (f != "ascii")
        refuse(name, at,
               "unknown format '" + excerpt(f) +
                   "' (ascii, binary_little_endian or binary_big_endian)");
    } else if (w[0] == "element") {
      if (!format) refuse(name, at, "an element before the format line");
      if (w.size() != 3) refuse(name, at, "expected 'element NAME COUNT'");
      Element e{std::string(w[1]), 0, h.lines, {}, 0};
      auto [ptr, ec] = std::from_chars(w[2].data(), w[2].data() + w[2].size(), e.count);
      if (ec != std::errc() || ptr != w[2].data() + w[2].size())
        refuse(name, at,
               "the element '" + excerpt(e.name) + "' has no count that a file can hold, got '" +
                   excerpt(w[2]) + "'");
      h.elements.push_back(std::move(e));
    } else if (w[0] == "property") {
      headerProperty(w, h, name, at);
    } else {
      refuse(name, at, "unknown header line '" + excerpt(w[0]) + "'");
    }
  }
  if (!ended)
    throw std::invalid_argument(name + ": the PLY header has no end_header line within its first " +
                                std::to_string(kMaxPlyHeaderBytes >> 10) + " KiB");
  h.bytes = std::min(pos, s.size());
  return h;
}

/// Refuses element counts the file cannot hold (each element takes at least its least_bytes) or
/// that exceed what a mesh may have (kMaxMeshTriangles faces, kMaxMeshVertices of the others).
void checkCounts(const Header& h, const std::string& name, size_t bytes) {
  uint64_t left = bytes - h.bytes + 1;  // +1: no newline after the last line
  for (const Element& e : h.elements) {
    const std::string what = name + ": the PLY header (line " + std::to_string(e.line) +
                             ") declares " + std::to_string(e.count) + " '" + excerpt(e.name) +
                             "' elements";
    const uint64_t most = e.name == "face" ? kMaxMeshTriangles : kMaxMeshVertices;
    if (e.count > most)
      throw std::invalid_argument(what + ", more than a mesh may have (at most " +
                                  std::to_string(most) + ")");
    if (e.least_bytes > 0 && e.count > left / e.least_bytes)
      throw std::invalid_argument(what + " of at least " + std::to_string(e.least_bytes) +
                                  " bytes each, more than the file's " + std::to_string(bytes) +
                                  " bytes can hold");
    left -= e.count * e.least_bytes;
  }
}

/// The element being read, for messages ("the face 3"), put in words only for one.
struct Item {
  const std::string& element;
  uint64_t index;
};

std::string str(const Item& i) {
  return "the " + excerpt(i.element) + " " + std::to_string(i.index);
}

/// The data after the header, one scalar at a time, ASCII or binary.
class Data {
 public:
  Data(std::string_view s, const Header& h, const std::string& name)
      : s_(s), pos_(h.bytes), format_(h.format), tokens_(s, h.bytes, h.lines + 1), name_(name) {}

  Where where() const {
    return format_ == Format::ascii ? Where{true, tokens_.line()} : Where{false, pos_};
  }
  size_t left() const { return format_ == Format::ascii ? tokens_.left() : s_.size() - pos_; }

  /// Where the last value read lies (its line, or its first byte's offset).
  Where last() const { return last_; }

  /// The next scalar of type t, of the element `what` ("the face 3").
  double value(Scalar t, const Item& what) {
    if (format_ != Format::ascii) last_ = where();
    const double v = format_ == Format::ascii ? textValue(t, what) : binaryValue(t, what);
    if (format_ == Format::ascii) last_ = where();
    return v;
  }

  /// Skips n scalars of type t (n at most the bytes left: a list's count is checked first).
  void skip(Scalar t, uint64_t n, const Item& what) {
    if (format_ != Format::ascii) {
      const uint64_t bytes = n * info(t).bytes;
      if (bytes > s_.size() - pos_) refuse(name_, where(), "the file ends inside " + str(what));
      pos_ += size_t(bytes);
      return;
    }
    std::string_view tok;
    for (uint64_t k = 0; k < n; ++k)
      if (!tokens_.next(tok)) refuse(name_, where(), "the file ends inside " + str(what));
  }

 private:
  double textValue(Scalar t, const Item& what) {
    std::string_view tok;
    if (!tokens_.next(tok)) refuse(name_, where(), "the file ends inside " + str(what));
    const ScalarInfo& i = info(t);
    double v = 0.0;
    if (i.integer) {
      int64_t n = 0;
      if (!mesh_io::parseInteger(tok, n) || double(n) < i.lo || double(n) > i.hi)
        refuse(name_, where(),
               str(what) + ": '" + excerpt(tok) + "' is not an integer of the type " + i.names[0]);
      v = double(n);
    } else if (!mesh_io::parseReal(tok, v)) {
      refuse(name_, where(), str(what) + ": '" + excerpt(tok) + "' is not a number");
    }
    return v;
  }

  double binaryValue(Scalar t, const Item& what) {
    const size_t n = info(t).bytes;
    if (s_.size() - pos_ < n) refuse(name_, where(), "the file ends inside " + str(what));
    unsigned char b[8];
    std::memcpy(b, s_.data() + pos_, n);
    pos_ += n;
    if (format_ == Format::big)
      for (size_t k = 0; k < n / 2; ++k) std::swap(b[k], b[n - 1 - k]);
    auto as = [&](auto x) {
      std::memcpy(&x, b, sizeof x);
      return double(x);
    };
    switch (t) {
      case Scalar::i8:
        return as(int8_t());
      case Scalar::u8:
        return as(uint8_t());
      case Scalar::i16:
        return as(int16_t());
      case Scalar::u16:
        return as(uint16_t());
      case Scalar::i32:
        return as(int32_t());
      case Scalar::u32:
        return as(uint32_t());
      case Scalar::f32:
        return as(float());
      default:
        return as(double());
    }
  }

  std::string_view s_;
  size_t pos_;
  Format format_;
  mesh_io::Tokens tokens_;
  const std::string& name_;
  Where last_;
};

/// The index of the face's corner list among `e`'s properties; refuses a face element without one.
size_t cornerList(const Element& e, const std::string& name) {
  for (size_t k = 0; k < e.props.size(); ++k)
    if (e.props[k].list &&
        (e.props[k].name == "vertex_indices" || e.props[k].name == "vertex_index")) {
      if (!info(e.props[k].type).integer)
        refuse(name, Where{true, e.line},
               "the face's " + excerpt(e.props[k].name) + " must be of an integer type");
      return k;
    }
  refuse(name, Where{true, e.line},
         "the element 'face' has no list property 'vertex_indices' (or 'vertex_index')");
}

/// Where x, y and z lie among the vertex element's properties.
std::array<size_t, 3> coordinates(const Element& e, const std::string& name) {
  std::array<size_t, 3> at{};
  for (size_t a = 0; a < 3; ++a) {
    const std::string want(1, "xyz"[a]);
    size_t found = e.props.size();
    for (size_t k = 0; k < e.props.size() && found == e.props.size(); ++k)
      if (e.props[k].name == want) found = k;
    if (found == e.props.size() || e.props[found].list)
      refuse(name, Where{true, e.line},
             "the element 'vertex' has no scalar property '" + want + "'");
    at[a] = found;
  }
  return at;
}

/// A list's count, checked against the bytes left: each item takes its bytes in binary, at least
/// two (a digit and a separator, the last one's newline may be missing) in ASCII.
uint64_t listCount(Data& d, const Property& p, bool ascii, const Item& what,
                   const std::string& name) {
  const double n = d.value(p.count, what);
  const Where at = d.last();
  if (n < 0)
    refuse(name, at,
           str(what) + " declares a list '" + excerpt(p.name) + "' of " +
               std::to_string(int64_t(n)) + " items");
  const uint64_t count = uint64_t(n);
  const uint64_t each = ascii ? 2 : info(p.type).bytes;
  if (count > (d.left() + (ascii ? 1 : 0)) / each)
    refuse(name, at,
           str(what) + " declares a list '" + excerpt(p.name) + "' of " + std::to_string(count) +
               " items, more than the " + std::to_string(d.left()) +
               " bytes left in the file can hold");
  return count;
}

}  // namespace

TriangleMesh parsePly(std::string_view s, const std::string& name) {
  const Header h = plyHeader(s, name);
  checkCounts(h, name, s.size());
  const bool ascii = h.format == Format::ascii;
  const Element* vertex = nullptr;
  const Element* face = nullptr;
  for (const Element& e : h.elements) {
    const Element*& slot = e.name == "vertex" ? vertex : face;
    if (e.name != "vertex" && e.name != "face") continue;
    if (slot) refuse(name, Where{true, e.line}, "a second element '" + excerpt(e.name) + "'");
    slot = &e;
  }
  const std::array<size_t, 3> xyz = vertex ? coordinates(*vertex, name) : std::array<size_t, 3>{};
  const size_t corners = face ? cornerList(*face, name) : 0;
  std::vector<glm::dvec3> v;
  v.reserve(vertex ? size_t(vertex->count) : 0);  // at most kMaxMeshVertices (checkCounts)
  mesh_io::Polygons faces(name, false);
  Data d(s, h, name);
  for (const Element& e : h.elements) {
    if (e.props.empty()) continue;  // takes no bytes
    const bool fixed =
        std::none_of(e.props.begin(), e.props.end(), [](const Property& p) { return p.list; });
    if (!ascii && fixed && &e != vertex) {  // skipped whole: count × least_bytes (checkCounts)
      d.skip(Scalar::u8, e.count * e.least_bytes, Item{e.name, e.count});
      continue;
    }
    for (uint64_t i = 0; i < e.count; ++i) {
      const Item what{e.name, i};
      glm::dvec3 p(0.0);
      for (size_t k = 0; k < e.props.size(); ++k) {
        const Property& pr = e.props[k];
        if (!pr.list && &e != vertex) {
          d.skip(pr.type, 1, what);
        } else if (!pr.list) {
          const double x = d.value(pr.type, what);
          for (size_t a = 0; a < 3; ++a)
            if (k == xyz[a]) {
              if (!std::isfinite(x))
                refuse(name, d.last(), str(what) + "'s " + "xyz"[a] + " is not a finite number");
              p[int(a)] = x;
            }
        } else {
          const uint64_t n = listCount(d, pr, ascii, what, name);
          if (&e != face || k != corners) {
            d.skip(pr.type, n, what);
            continue;
          }
          faces.begin(d.last());
          for (uint64_t c = 0; c < n; ++c) faces.corner(int64_t(d.value(pr.type, what)));
          faces.end();
        }
      }
      if (&e == vertex) v.push_back(p);
    }
  }
  return faces.finish(std::move(v));
}

}  // namespace eikon
