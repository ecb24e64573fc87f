// eikon's own readers of the three mesh formats (core/scene/mesh.h readMesh calls them): Wavefront
// OBJ, PLY (ascii, binary_little_endian, binary_big_endian) and STL (ASCII and binary). Each
// takes the file's bytes in memory and a name for its messages, so that a fuzzer calls it without
// files, and returns the file's vertices in double (as written: a coordinate written with 17
// digits is read to the last bit) and its polygons as triangles, unwelded (readMesh welds equal
// positions).
//
// The readers are written for hostile input: every count a file declares (a PLY element's, a
// PLY face's list, a binary STL's triangles) is checked against the bytes that remain before
// anything is allocated for it, and against the mesh limits (kMaxMeshTriangles,
// kMaxMeshVertices); every index is range-checked; a face of fewer than 3 corners, a point or a
// line element, and a NaN or infinite coordinate are refused. No reader opens another file (an
// OBJ's mtllib and usemtl lines are ignored). Each refusal is one std::invalid_argument
// "NAME: line N: why" (text) or "NAME: byte offset N: why" (binary).
//
// Polygons are triangulated as Assimp did: a quad from its concave corner (if it has one), any
// other polygon as a fan from its first corner (convex polygons, as exporters write them).
#pragma once

#include <string>
#include <string_view>

#include "core/scene/mesh.h"

namespace eikon {

/// OBJ: `v x y z` (an optional w, or r g b after them), `f` lines of 3 or more corners written
/// `v`, `v/vt`, `v//vn` or `v/vt/vn` (1-based; negative counts back from the last vertex read);
/// `vt` and `vn` counted so that their indices are range-checked; a line ending in `\` continues
/// on the next; `#` starts a comment. `l` and `p` (points, lines) are refused; every other
/// statement (o, g, s, mtllib, usemtl, vp, ...) is ignored.
TriangleMesh parseObj(std::string_view bytes, const std::string& name);

/// PLY 1.0, ascii or binary of either byte order: the element `vertex` with scalar properties x,
/// y and z of any numeric type; the element `face` with a list property `vertex_indices` (or
/// `vertex_index`) of any integer count and index types. Every other element and property is
/// skipped by its size. The header must end within kMaxPlyHeaderBytes.
TriangleMesh parsePly(std::string_view bytes, const std::string& name);

/// STL: binary when the size is 84 + 50·n for the n its bytes 80–83 declare (little-endian),
/// otherwise ASCII (`solid`, then `facet normal`, `outer loop`, three `vertex` lines, `endloop`,
/// `endfacet`, ..., `endsolid`; several solids may follow each other).
TriangleMesh parseStl(std::string_view bytes, const std::string& name);

/// Longest PLY header read (a real header is a few hundred bytes).
constexpr size_t kMaxPlyHeaderBytes = 64u << 10;

}  // namespace eikon
