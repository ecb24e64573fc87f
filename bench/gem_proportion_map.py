#!/usr/bin/python3
"""The round brilliant's proportion map: eikon gem's brightness and fire over crown angle x
pavilion angle, with the face-up table's dark share (nailhead) and leaking share (windowing),
for the comparison with GIA's published trends (docs/gem-studio.md "Proportion map").

  PYTHONPATH=build/python /usr/bin/python3 bench/gem_proportion_map.py \
      [--crown 25:40:2.5] [--pavilion 37:45:0.5] [--tilts 0] [--size 64] [--spp 4] \
      [--threads 2] [-o docs/images/gem_proportions.png] [--csv FILE] [--replot CSV]

Each grid point is scenes/diamond_brilliant.json (table 57%, girdle 2%, 16 facets around) with
its crown_deg and pavilion_deg replaced, analysed by eikon.gem at the given tilts (face-up by
default: the nailhead and the fisheye are face-up effects). The defaults, 7 x 17 stones at
64 x 64, take about 7 minutes on 2 cores (3.5 s a stone; at one tilt the five presets' images
are made once, at the first stone, and kept). Progress by tqdm on stderr; --replot draws the map
again from the CSV --csv wrote (docs/figures/gem_proportions.csv holds the shipped map's).

The table region is the pixels within 0.9 of the table's inradius (0.57 x 5 mm) of the stone's
centre, the pixel size following eikon gem's framing (docs/gem-studio.md "Viewing": 5% over the
bounding sphere of the stone's bounding box, a cube of the shape's bounding radius). Face-up, a
table pixel is dark when its dome luminance is below 0.25 of the white diffuser's, cos^2 23 deg
(the extinction metric's threshold) and leaks when more than half its light is the
Ideal-scope's backlight (the windowing metric's).
"""
import argparse
import csv
import json
import math
import os
import sys
import time

import numpy as np
from tqdm import tqdm

import eikon

HERE = os.path.dirname(os.path.abspath(__file__))
SCENE = os.path.join(HERE, "..", "scenes", "diamond_brilliant.json")
DIAMETER, TABLE, GIRDLE, FACETS = 10.0, 0.57, 0.02, 16
WHITE_FACE_UP = math.cos(math.radians(23.0)) ** 2  # the dome's white diffuser, face-up
N_D = 2.417486  # the scene's diamond at 587.56 nm


def grid(text):
    """FROM:TO:STEP (inclusive) or a comma-separated list."""
    if ":" in text:
        lo, hi, step = (float(v) for v in text.split(":"))
        n = int(math.floor((hi - lo) / step + 1e-9)) + 1
        return [round(lo + k * step, 6) for k in range(n)]
    return [float(v) for v in text.split(",")]


def bounding_radius(crown, pavilion):
    """The brilliant's farthest vertex from its centre (core/scene/shapes.cpp makeBrilliant)."""
    r, h = 0.5 * DIAMETER, 0.5 * GIRDLE * DIAMETER
    vertex = 1.0 / math.cos(math.pi / FACETS)
    table_y = h + (r - TABLE * r) * math.tan(math.radians(crown))
    return max(math.hypot(r * vertex, h), h + r * math.tan(math.radians(pavilion)),
               math.hypot(TABLE * r * vertex, table_y))


def table_mask(size, crown, pavilion):
    half_mm = 1.05 * math.sqrt(3.0) * bounding_radius(crown, pavilion)  # the frame's half-width
    c = (np.arange(size) + 0.5) / size * 2.0 - 1.0
    x, y = np.meshgrid(c * half_mm, c * half_mm)
    return np.hypot(x, y) < 0.9 * TABLE * 0.5 * DIAMETER


def scene_for(base, crown, pavilion):
    j = json.loads(json.dumps(base))
    stone = j["objects"][0]
    stone["crown_deg"], stone["pavilion_deg"] = crown, pavilion
    # The volume holds the deepest pavilion and highest crown of the map.
    j["volume"]["bounds_min"] = [-5.6, -(0.2 + 5.0 * math.tan(math.radians(pavilion))), -5.6]
    j["volume"]["bounds_max"] = [5.6, 0.3 + 2.15 * math.tan(math.radians(crown)), 5.6]
    j["volume"]["resolution"] = 96
    return eikon.Scene.parse(j, SCENE)


def analyse(base, crown, pavilion, a):
    g = eikon.gem(scene_for(base, crown, pavilion), tilts=a.tilts, width=a.size, height=a.size,
                  spp=a.spp, wavelengths=a.wavelengths, threads=a.threads, keep_images=True)
    face_up = min(range(len(a.tilts)), key=lambda k: abs(a.tilts[k]))
    dome = g["images"][f"dome_{face_up}"]
    scope = g["images"]["idealscope"]
    mask = table_mask(a.size, crown, pavilion)
    y = dome @ np.array([0.2126, 0.7152, 0.0722], dtype=np.float32)
    row = {k: g[k] for k in ("brightness", "fire", "scintillation", "windowing", "extinction")}
    row["table_dark"] = float(np.mean(y[mask] < 0.25 * WHITE_FACE_UP))
    row["table_leak"] = float(np.mean(scope[..., 1][mask] > 0.5))
    row["face_up_brightness"] = g["per_tilt"][face_up]["brightness"]
    return row


def girdle_band(pavilion):
    """The table radii whose face-up ray, after its first pavilion reflection, meets the far
    girdle (tests/core/session/gem_test.cpp, the fisheye test): (lo, hi) in mm."""
    r, g = 0.5 * DIAMETER, 0.5 * GIRDLE * DIAMETER
    p = math.radians(pavilion)
    slope = math.tan(math.pi / 2 - 2 * p)
    y0, dy = -g - r * math.tan(p) + r * slope, math.tan(p) + slope
    return (-g - y0) / dy, (g - y0) / dy


def crown_shadow_pavilions(crown, head_deg=23.0):
    """The pavilion angles between which a face-up table ray, reflected by two opposite pavilion
    mains (leaving them 180 - 4p off the vertical, outwards) and out through the far crown main,
    leaves within head_deg of the view: crown - asin(n sin(crown + 4p - 180)) = +-head_deg."""
    out = []
    for sign in (1.0, -1.0):
        s = math.sin(math.radians(crown - sign * head_deg)) / N_D
        out.append((180.0 - crown + math.degrees(math.asin(s))) / 4.0)
    return out


def limits():
    critical = math.degrees(math.asin(1.0 / N_D))
    # Two table reflections return a face-up ray 180 - 4p off the view; through the table, inside
    # the 23 deg head shadow (refracted into the stone) the table shows the observer's head.
    head = (180.0 - math.degrees(math.asin(math.sin(math.radians(23.0)) / N_D))) / 4.0
    fisheye = max(p / 100.0 for p in range(3000, 4500)
                  if girdle_band(p / 100.0)[1] < TABLE * 0.5 * DIAMETER)
    return critical, head, fisheye


def plot(crowns, pavilions, maps, out):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    _, head_limit, fisheye = limits()
    band = np.array([crown_shadow_pavilions(c) for c in crowns])
    panels = [("brightness", "brightness (dome, / white diffuser)", "viridis"),
              ("fire", "fire (spot, coloured share)", "magma"),
              ("table_dark", "face-up table: dark share", "Greys"),
              ("table_leak", "face-up table: leaking share (windowing)", "Blues")]
    fig, axes = plt.subplots(2, 2, figsize=(12, 9), dpi=100, constrained_layout=True)
    extent = [pavilions[0], pavilions[-1], crowns[0], crowns[-1]]
    for ax, (key, title, cmap) in zip(axes.flat, panels):
        z = maps[key]
        im = ax.imshow(z, origin="lower", extent=extent, aspect="auto", cmap=cmap,
                       interpolation="bilinear")
        if z.shape[0] > 1 and z.shape[1] > 1:
            ax.contour(pavilions, crowns, z, levels=6, colors="white", linewidths=0.6,
                       alpha=0.7)
        fig.colorbar(im, ax=ax, shrink=0.9)
        if key in ("brightness", "fire"):
            i, j = np.unravel_index(np.argmax(z), z.shape)
            ax.plot(pavilions[j], crowns[i], "w*", ms=12, mec="k")
        ax.plot(band[:, 0], crowns, color="tab:red", ls="--", lw=1.2)
        ax.plot(band[:, 1], crowns, color="tab:red", ls="--", lw=1.2)
        ax.axvline(head_limit, color="tab:orange", ls="--", lw=1)
        ax.axvline(fisheye, color="tab:cyan", ls=":", lw=1.2)
        ax.plot(40.75, 34.5, "P", color="tab:red", ms=9, mec="w")
        ax.set_xlim(pavilions[0], pavilions[-1])
        ax.set_title(title)
        ax.set_xlabel("pavilion angle (deg)")
        ax.set_ylabel("crown angle (deg)")
    fig.suptitle("Round brilliant in diamond (table 57%, 16 mains), eikon gem face-up; +: the "
                 "shipped 34.5/40.75\nred: between, table rays leave by the far crown into "
                 f"the 23 deg head shadow; orange {head_limit:.1f} deg: by the table into it "
                 f"(nailhead); cyan {fisheye:.1f} deg: girdle in table (fisheye)", fontsize=9)
    fig.savefig(out)


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--crown", default="25:40:2.5")
    p.add_argument("--pavilion", default="37:45:0.5")
    p.add_argument("--tilts", default="0")
    p.add_argument("--size", type=int, default=64)
    p.add_argument("--spp", type=int, default=4)
    p.add_argument("--wavelengths", type=int, default=8)
    p.add_argument("--threads", type=int, default=0)
    p.add_argument("-o", "--output", default=os.path.join(HERE, "..", "docs", "images",
                                                         "gem_proportions.png"))
    p.add_argument("--csv", help="also write the grid's figures as CSV")
    p.add_argument("--replot", metavar="CSV", help="draw the map from a CSV --csv wrote")
    a = p.parse_args()
    keys = ("brightness", "fire", "scintillation", "windowing", "extinction", "table_dark",
            "table_leak", "face_up_brightness")
    if a.replot:
        with open(a.replot) as f:
            rows = list(csv.DictReader(f))
        crowns = sorted({float(r["crown_deg"]) for r in rows})
        pavilions = sorted({float(r["pavilion_deg"]) for r in rows})
        maps = {k: np.zeros((len(crowns), len(pavilions))) for k in keys}
        for r in rows:
            i, j = crowns.index(float(r["crown_deg"])), pavilions.index(float(r["pavilion_deg"]))
            for k in keys:
                maps[k][i, j] = float(r[k])
        plot(np.array(crowns), np.array(pavilions), maps, a.output)
        return
    try:
        crowns, pavilions, a.tilts = grid(a.crown), grid(a.pavilion), grid(a.tilts)
    except ValueError as e:
        sys.exit(f"gem_proportion_map: bad grid: {e}")
    with open(SCENE) as f:
        base = json.load(f)
    base["environment"] = {"preset": "dome"}
    maps = {k: np.zeros((len(crowns), len(pavilions))) for k in keys}
    rows = []
    start = time.time()
    cells = [(i, j) for i in range(len(crowns)) for j in range(len(pavilions))]
    for i, j in tqdm(cells, desc="stones", unit="stone", file=sys.stderr):
        row = analyse(base, crowns[i], pavilions[j], a)
        for k in keys:
            maps[k][i, j] = row[k]
        rows.append({"crown_deg": crowns[i], "pavilion_deg": pavilions[j], **row})
    if a.csv:
        with open(a.csv, "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=list(rows[0]))
            w.writeheader()
            w.writerows(rows)
    plot(np.array(crowns), np.array(pavilions), maps, a.output)
    print(f"{len(cells)} stones in {time.time() - start:.0f} s; map in {a.output}")
    for k in ("brightness", "fire"):
        i, j = np.unravel_index(np.argmax(maps[k]), maps[k].shape)
        print(f"  highest {k} {maps[k][i, j]:.4f} at crown {crowns[i]}, pavilion {pavilions[j]}")
        print(f"  best pavilion per crown ({k}): " + ", ".join(
            f"{c}: {pavilions[int(np.argmax(maps[k][r]))]}" for r, c in enumerate(crowns)))


if __name__ == "__main__":
    main()
