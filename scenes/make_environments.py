#!/usr/bin/env python3
"""Writes the latlong environments of two scenes (standard library only, no numpy/OpenEXR):

scenes/prism_bk7_slit.exr (scenes/prism_bk7.json): a dark sky (radiance 0.02) with one narrow bright vertical slit (radiance 40, one texel = 0.088°
wide, ±1.4° of latitude) in the world direction (-cos 19.323°, 0, -sin 19.323°): the direction
from which d-line light (587.56 nm) passes the scene's N-BK7 prism at minimum deviation and
reaches the camera. Latlong convention of core/scene/scene.cpp (Environment::lookup):
u = atan2(x, -z)/(2π) + 0.5, v = acos(y)/π, rows from the top. 
scenes/diamond_lights.exr (scenes/diamond_brilliant.json): a black sky with 40 small bright
round lights (radiance 30, radius 1.5°) scattered over the upper hemisphere (fixed seed), and a
faint floor glow (0.01) below: point-like sources make the coloured flashes ("fire") of a
brilliant visible instead of washing them out.
scenes/polariscope_lightbox.exr (scenes/polariscope_gems_*.json): a polariscope's light box, white
(radiance 1) below the horizon and black above, so that only light that came up through the
polariser sheet reaches the camera (light from above would pass the analyser alone and veil the
stones' extinction).

All are half-float, ZIPS-compressed scanline OpenEXR files (a few tens of kB).

    python3 scenes/make_environments.py         # rewrites both .exr files next to this script
"""
import math
import os
import struct
import zlib

W, H = 4096, 256
SKY, SLIT = 0.02, 40.0
HALF_DEV = 19.3234           # D_min(d)/2 for N-BK7, A = 60°
LAT_HALF_DEG = 1.4


def slit_column():
    d = (-math.cos(math.radians(HALF_DEV)), 0.0, -math.sin(math.radians(HALF_DEV)))
    u = math.atan2(d[0], -d[2]) / (2 * math.pi) + 0.5
    return int(u * W)  # texel whose centre is nearest u·W − 0.5 rounds down; one texel wide


def attr(name, typ, data):
    return name.encode() + b"\0" + typ.encode() + b"\0" + struct.pack("<i", len(data)) + data


def zip_block(raw):
    # OpenEXR ZIP(S) preprocessing: interleave bytes (even, then odd), then delta predictor.
    t = raw[0::2] + raw[1::2]
    out = bytearray(len(t))
    prev = 0
    for i, b in enumerate(t):
        out[i] = (b - prev + 128 + 256) & 0xFF if i else b
        prev = b
    return zlib.compress(bytes(out), 9)


def write_exr(path, W, H, row_fn):
    """row_fn(y) -> list of W grey radiances for scanline y (top row first)."""
    chans = b"".join(c.encode() + b"\0" + struct.pack("<iBBBBii", 1, 0, 0, 0, 0, 1, 1) for c in "BGR") + b"\0"
    header = b"".join([
        attr("channels", "chlist", chans),
        attr("compression", "compression", bytes([2])),  # ZIPS_COMPRESSION, one scanline per block
        attr("dataWindow", "box2i", struct.pack("<iiii", 0, 0, W - 1, H - 1)),
        attr("displayWindow", "box2i", struct.pack("<iiii", 0, 0, W - 1, H - 1)),
        attr("lineOrder", "lineOrder", bytes([0])),
        attr("pixelAspectRatio", "float", struct.pack("<f", 1.0)),
        attr("screenWindowCenter", "v2f", struct.pack("<ff", 0.0, 0.0)),
        attr("screenWindowWidth", "float", struct.pack("<f", 1.0)),
    ]) + b"\0"
    blocks = []
    for y in range(H):
        row = row_fn(y)
        line = struct.pack("<%de" % W, *row)
        raw = line * 3  # B, G, R planes of this scanline (grey)
        comp = zip_block(raw)
        if len(comp) >= len(raw):
            comp = raw
        blocks.append(struct.pack("<ii", y, len(comp)) + comp)
    start = 8 + len(header) + 8 * H
    offsets, pos = [], start
    for b in blocks:
        offsets.append(pos)
        pos += len(b)
    data = struct.pack("<ii", 20000630, 2) + header + struct.pack("<%dQ" % H, *offsets) + b"".join(blocks)
    with open(path, "wb") as f:
        f.write(data)
    print("wrote %s (%dx%d, %d bytes)" % (path, W, H, len(data)))


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    col = slit_column()
    lat_rows = [y for y in range(H) if abs(90.0 - (y + 0.5) * 180.0 / H) <= LAT_HALF_DEG]
    print("slit: column %d, rows %d-%d" % (col, lat_rows[0], lat_rows[-1]))

    def slit_row(y):
        row = [SKY] * W
        if y in lat_rows:
            row[col] = SLIT
        return row

    write_exr(os.path.join(here, "prism_bk7_slit.exr"), W, H, slit_row)

    # Diamond lights: directions uniform on the upper hemisphere above 15° elevation.
    import random
    rng = random.Random(4)
    dw, dh, radius, lights = 1024, 512, math.radians(1.5), []
    for _ in range(40):
        y = rng.uniform(math.sin(math.radians(15)), 1.0)
        phi = rng.uniform(0, 2 * math.pi)
        r = math.sqrt(1 - y * y)
        lights.append((r * math.cos(phi), y, r * math.sin(phi)))
    cosr = math.cos(radius)

    def light_row(yy):
        theta = (yy + 0.5) / dh * math.pi
        row = []
        for xx in range(dw):
            u = (xx + 0.5) / dw
            ang = (u - 0.5) * 2 * math.pi          # u = atan2(x, -z)/2π + 0.5
            d = (math.sin(theta) * math.sin(ang), math.cos(theta), -math.sin(theta) * math.cos(ang))
            v = 0.01 if d[1] < 0 else 0.0
            for l in lights:
                if d[0] * l[0] + d[1] * l[1] + d[2] * l[2] >= cosr:
                    v = 30.0
                    break
            row.append(v)
        return row

    write_exr(os.path.join(here, "diamond_lights.exr"), dw, dh, light_row)

    # Polariscope light box: rows below the horizon (texel centre v > ½) white, above black.
    lw, lh = 64, 32
    write_exr(os.path.join(here, "polariscope_lightbox.exr"), lw, lh,
              lambda yy: [1.0 if yy >= lh // 2 else 0.0] * lw)


if __name__ == "__main__":
    main()
