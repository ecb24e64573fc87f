#!/usr/bin/python3
"""Writes the self-made test meshes of tests/data/meshes: run it from anywhere,
it writes next to itself. Every file is generated here, none is downloaded.

  box.obj            the cube [-0.5, 0.5]^3 as 6 quads (the reader triangulates them), outward
  box.stl            the same cube as 12 triangles, binary STL (corners stored per triangle)
  box.ply            the same cube as 12 triangles, ASCII PLY
  icosphere2.obj     the unit icosphere of subdivision level 2 (320 triangles, vertices on r = 1)
  open_box.obj       box.obj without its +z face: the four edges around the hole are open
  fin_box.obj        box.obj plus a fin triangle on the edge (0.5, 0.5, -0.5)-(0.5, 0.5, 0.5):
                     that edge is shared by three triangles (non-manifold)
  flipped_face.obj   box.obj with the +x face wound clockwise (inconsistent orientation)
  inward_box.obj     box.obj with every face wound clockwise (consistent, but facing inward)
  notched_box.obj    a closed L-shaped prism (non-convex)
  notched_prism.obj  the equilateral prism of side 3 (apex (0, sqrt 3), base y = -sqrt(3)/2, the
                     light tests' apex prism) with a notch 0.15 deep in its base at x = 1.25..1.45,
                     so that it is not convex; z from -10 to 10
  lines.obj          a triangle and a line element (not a surface)

and the meshes of the shipped scenes:

  scenes/meshes/icosphere2.obj   the unit icosphere of level 2 (320 triangles)
  scenes/meshes/torus.obj        a ring torus about the y axis, radii 1 and 0.4, 48 × 24 quads
"""
import math
import os
import struct

HERE = os.path.dirname(os.path.abspath(__file__))

CUBE_V = [(x, y, z) for x in (-0.5, 0.5) for y in (-0.5, 0.5) for z in (-0.5, 0.5)]
# Quads counter-clockwise seen from outside (0-based into CUBE_V: index = 4*ix + 2*iy + iz).
CUBE_Q = [
    (4, 6, 7, 5),  # +x
    (0, 1, 3, 2),  # -x
    (2, 3, 7, 6),  # +y
    (0, 4, 5, 1),  # -y
    (1, 5, 7, 3),  # +z
    (0, 2, 6, 4),  # -z
]


def tris_of(quads):
    return [t for a, b, c, d in quads for t in ((a, b, c), (a, c, d))]


def write_obj(name, verts, faces, extra=""):
    with open(os.path.join(HERE, name), "w") as f:
        f.write("# self-made by make_meshes.py (eikon tests)\n")
        for v in verts:
            f.write("v %.17g %.17g %.17g\n" % v)
        for face in faces:
            f.write("f " + " ".join(str(i + 1) for i in face) + "\n")
        f.write(extra)


def write_stl(name, verts, tris):
    with open(os.path.join(HERE, name), "wb") as f:
        f.write(b"self-made by make_meshes.py (eikon tests)".ljust(80, b" "))
        f.write(struct.pack("<I", len(tris)))
        for t in tris:
            p = [verts[i] for i in t]
            u = [p[1][k] - p[0][k] for k in range(3)]
            w = [p[2][k] - p[0][k] for k in range(3)]
            n = (u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0])
            f.write(struct.pack("<3f", *n))
            for q in p:
                f.write(struct.pack("<3f", *q))
            f.write(struct.pack("<H", 0))


def write_ply(name, verts, tris):
    with open(os.path.join(HERE, name), "w") as f:
        f.write("ply\nformat ascii 1.0\ncomment self-made by make_meshes.py (eikon tests)\n")
        f.write("element vertex %d\nproperty float x\nproperty float y\nproperty float z\n" % len(verts))
        f.write("element face %d\nproperty list uchar int vertex_indices\nend_header\n" % len(tris))
        for v in verts:
            f.write("%.9g %.9g %.9g\n" % v)
        for t in tris:
            f.write("3 %d %d %d\n" % t)


def icosphere(level):
    p = (1 + math.sqrt(5)) / 2
    v = [(-1, p, 0), (1, p, 0), (-1, -p, 0), (1, -p, 0), (0, -1, p), (0, 1, p), (0, -1, -p),
         (0, 1, -p), (p, 0, -1), (p, 0, 1), (-p, 0, -1), (-p, 0, 1)]
    v = [tuple(c / math.sqrt(1 + p * p) for c in x) for x in v]
    f = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4),
         (11, 10, 2), (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8),
         (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    for _ in range(level):
        mid = {}

        def m(a, b):
            key = (min(a, b), max(a, b))
            if key not in mid:
                c = [(v[a][k] + v[b][k]) / 2 for k in range(3)]
                r = math.sqrt(sum(x * x for x in c))
                v.append(tuple(x / r for x in c))
                mid[key] = len(v) - 1
            return mid[key]

        f = [t for a, b, c in f for t in ((a, m(a, b), m(c, a)), (b, m(b, c), m(a, b)),
                                          (c, m(c, a), m(b, c)), (m(a, b), m(b, c), m(c, a)))]
    return v, f


def torus(big, small, nu, nv):
    v = []
    for i in range(nu):
        u = 2 * math.pi * i / nu
        for j in range(nv):
            w = 2 * math.pi * j / nv
            rr = big + small * math.cos(w)
            v.append((rr * math.cos(u), small * math.sin(w), rr * math.sin(u)))
    q = [(i * nv + j, i * nv + (j + 1) % nv, ((i + 1) % nu) * nv + (j + 1) % nv, ((i + 1) % nu) * nv + j)
         for i in range(nu) for j in range(nv)]
    return v, q


def main():
    write_obj("box.obj", CUBE_V, CUBE_Q)
    write_stl("box.stl", CUBE_V, tris_of(CUBE_Q))
    write_ply("box.ply", CUBE_V, tris_of(CUBE_Q))
    v, f = icosphere(2)
    write_obj("icosphere2.obj", v, f)
    write_obj("open_box.obj", CUBE_V, [q for q in CUBE_Q if q != (1, 5, 7, 3)])
    write_obj("fin_box.obj", CUBE_V + [(1.0, 0.75, 0.0)], CUBE_Q + [(6, 7, 8)])
    write_obj("flipped_face.obj", CUBE_V, [CUBE_Q[0][::-1]] + CUBE_Q[1:])
    write_obj("inward_box.obj", CUBE_V, [q[::-1] for q in CUBE_Q])
    # An L-shaped prism: the profile (0,0) (2,0) (2,1) (1,1) (1,2) (0,2) extruded along z by 1.
    prof = [(0, 0), (2, 0), (2, 1), (1, 1), (1, 2), (0, 2)]
    lv = [(x, y, z) for z in (0.0, 1.0) for x, y in prof]
    caps = [(0, 2, 1), (0, 3, 2), (0, 5, 3), (3, 5, 4), (6, 7, 8), (6, 8, 9), (6, 9, 11), (9, 10, 11)]
    sides = [(k, (k + 1) % 6, (k + 1) % 6 + 6, k + 6) for k in range(6)]
    write_obj("notched_box.obj", lv, caps + sides)
    # The apex prism with a notch in its base: profile counter-clockwise seen from +z, the caps
    # fanned from the apex (index 5), which sees every corner.
    h = math.sqrt(3.0) / 2
    prof = [(-1.5, -h), (1.25, -h), (1.35, -h + 0.15), (1.45, -h), (1.5, -h), (0.0, 2 * h)]
    pv = [(x, y, z) for z in (-10.0, 10.0) for x, y in prof]
    caps = [(5, k + 1, k) for k in range(4)] + [(11, k + 6, k + 7) for k in range(4)]
    sides = [(k, (k + 1) % 6, (k + 1) % 6 + 6, k + 6) for k in range(6)]
    write_obj("notched_prism.obj", pv, caps + sides)
    write_obj("lines.obj", [(0, 0, 0), (1, 0, 0), (0, 1, 0)], [(0, 1, 2)], "l 1 2\n")
    scenes = os.path.join(HERE, "..", "..", "..", "scenes", "meshes")
    os.makedirs(scenes, exist_ok=True)
    v, f = icosphere(2)
    write_obj(os.path.join(scenes, "icosphere2.obj"), v, f)
    v, q = torus(1.0, 0.4, 48, 24)
    write_obj(os.path.join(scenes, "torus.obj"), v, q)


if __name__ == "__main__":
    main()
