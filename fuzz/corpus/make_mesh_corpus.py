#!/usr/bin/python3
"""Writes the seed corpora of the mesh reader fuzzers (fuzz/mesh_obj.cpp, mesh_ply.cpp,
mesh_stl.cpp) into fuzz/corpus/mesh_{obj,ply,stl}/: a few tiny valid files of each format and
encoding, and invalid ones that exercise the refusals (a face list of 2^31 corners, a face of 0
corners, a file cut inside a face, an index out of range, mtllib lines). Run it from anywhere."""
import os
import struct

HERE = os.path.dirname(os.path.abspath(__file__))
V = [(x, y, z) for x in (-0.5, 0.5) for y in (-0.5, 0.5) for z in (-0.5, 0.5)]
Q = [(4, 6, 7, 5), (0, 1, 3, 2), (2, 3, 7, 6), (0, 4, 5, 1), (1, 5, 7, 3), (0, 2, 6, 4)]
T = [t for a, b, c, d in Q for t in ((a, b, c), (a, c, d))]
TET = ([(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)], [(0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)])


def write(sub, name, data):
    os.makedirs(os.path.join(HERE, sub), exist_ok=True)
    with open(os.path.join(HERE, sub, name), "wb") as f:
        f.write(data if isinstance(data, bytes) else data.encode())


def obj(verts, faces, head=""):
    return head + "".join("v %r %r %r\n" % v for v in verts) + \
        "".join("f " + " ".join(str(i + 1) for i in f) + "\n" for f in faces)


def ply_head(fmt, nv, nf, coord="float", count="uchar"):
    return ("ply\nformat %s 1.0\nelement vertex %d\nproperty %s x\nproperty %s y\nproperty %s z\n"
            "element face %d\nproperty list %s int vertex_indices\nend_header\n"
            % (fmt, nv, coord, coord, coord, nf, count))


def ply_ascii(verts, faces, count="uchar", first=None):
    body = "".join("%r %r %r\n" % v for v in verts)
    for k, f in enumerate(faces):
        n = len(f) if first is None or k else first
        body += " ".join(str(x) for x in (n,) + tuple(f)) + "\n"
    return ply_head("ascii", len(verts), len(faces), count=count) + body


def ply_binary(verts, faces, big=False, coord="float", count="uchar", first=None):
    e = ">" if big else "<"
    c = {"float": "f", "double": "d"}[coord]
    n = {"uchar": "B", "uint": "I"}[count]
    body = b"".join(struct.pack(e + 3 * c, *v) for v in verts)
    for k, f in enumerate(faces):
        m = len(f) if first is None or k else first
        body += struct.pack(e + n, m) + b"".join(struct.pack(e + "i", i) for i in f)
    fmt = "binary_big_endian" if big else "binary_little_endian"
    return ply_head(fmt, len(verts), len(faces), coord, count).encode() + body


def stl_ascii(verts, tris):
    s = "solid seed\n"
    for t in tris:
        s += " facet normal 0 0 0\n  outer loop\n"
        s += "".join("   vertex %r %r %r\n" % verts[i] for i in t)
        s += "  endloop\n endfacet\n"
    return s + "endsolid seed\n"


def stl_binary(verts, tris):
    b = b"seed".ljust(80, b" ") + struct.pack("<I", len(tris))
    for t in tris:
        b += struct.pack("<3f", 0, 0, 0) + b"".join(struct.pack("<3f", *verts[i]) for i in t)
        b += b"\0\0"
    return b


write("mesh_obj", "box.obj", obj(V, Q, "# cube\nmtllib box.mtl\no box\nusemtl glass\n"))
write("mesh_obj", "tetra.obj", obj(*TET))
write("mesh_obj", "forms.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\n"
      "f -4/1/1 -3//1 -2/1 -1\nf 1 2 \\\n 3\n")
write("mesh_obj", "mtllib.obj", "mtllib /etc/passwd\nmtllib pipe.mtl\n" + obj(*TET))
write("mesh_obj", "bad_index.obj", obj(TET[0], [(0, 1, 9)]))
write("mesh_obj", "line.obj", obj(TET[0], [(0, 1, 2)]) + "l 1 2\nf 1 2\n")
# An L-shaped prism whose caps are single concave hexagons (ear clipping), and a pentagram face.
L = [(3, 1), (1, 1), (1, 2), (0, 2), (0, 0), (3, 0)]
write("mesh_obj", "concave_l.obj", obj([(x, y, z) for z in (0, 1) for (x, y) in L],
                                        [tuple(range(5, -1, -1)), tuple(range(6, 12))] +
                                        [(k, (k + 1) % 6, 6 + (k + 1) % 6, 6 + k) for k in range(6)]))
write("mesh_obj", "pentagram.obj", "v 1 0 0\nv -0.809 0.588 0\nv 0.309 -0.951 0\n"
      "v 0.309 0.951 0\nv -0.809 -0.588 0\nf 1 2 3 4 5\n")
write("mesh_ply", "box_ascii.ply", ply_ascii(V, T))
write("mesh_ply", "box_le.ply", ply_binary(V, T))
write("mesh_ply", "tetra_be_double.ply", ply_binary(*TET, big=True, coord="double"))
write("mesh_ply", "huge_list_ascii.ply", ply_ascii(V, T, count="uint", first=2**31))
write("mesh_ply", "huge_list_le.ply", ply_binary(V, T, count="uint", first=2**31))
write("mesh_ply", "zero_corners.ply", ply_binary(*TET, first=0))
write("mesh_ply", "cut.ply", ply_binary(V, T)[:-5])
write("mesh_stl", "box_ascii.stl", stl_ascii(V, T))
write("mesh_stl", "box_binary.stl", stl_binary(V, T))
write("mesh_stl", "tetra_ascii.stl", stl_ascii(*TET))
write("mesh_stl", "cut_binary.stl", stl_binary(V, T)[:-7])
write("mesh_stl", "short.stl", "solid x\n facet normal 0 0 1\n  outer loop\n   vertex 0 0")
