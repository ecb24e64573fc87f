#!/usr/bin/python3
"""Module boundaries of the physics: optics/ (what a scene needs) never depends on fitting/ (the
`eikon fit` tool), nothing that touches a scene pulls in Ceres or yaml-cpp, and the two twins,
core/render (GPU) and core/reference (the CPU oracle), are siblings on core/light: neither
includes nor links the other, and core/light stands on neither.

Checked from the sources, so that a static-library chain cannot hide a dependency:
  - no file under optics/ or core/ includes a fitting/ header, or a Ceres, glog, Eigen or
    yaml-cpp header;
  - no CMakeLists.txt outside fitting/ links Ceres::ceres or yaml-cpp, and none under optics/ or
    core/ links eikon::fitting / eikon_fitting;
  - no file under core/render/ includes a core/reference/ header or the other way round, and no
    file under core/light/ includes either; no CMakeLists.txt there links the forbidden twin
    (eikon::render / eikon_render, eikon::reference / eikon_reference).
Each violation is printed as FILE:LINE: what.
usage: module_boundaries.py SOURCE_DIR   — prints "module_boundaries: N passed, M failed".
       module_boundaries.py --self-test  — runs the checks on a made-up tree with known defects.
"""
import os
import re
import subprocess
import sys
import tempfile

INCLUDE = re.compile(r'^\s*#\s*include\s*[<"]([^">]+)[">]')
FOREIGN_HEADERS = ("fitting/", "ceres/", "glog/", "Eigen/", "yaml-cpp/")
SOURCE_EXT = (".h", ".hpp", ".cpp", ".cc", ".inl")
CERES_OR_YAML = re.compile(r"\bCeres::\w+|\byaml-cpp\b")
FITTING_TARGET = re.compile(r"\beikon(::|_)fitting\b")
# Scene-side folders: what they include and link must stay free of the fitting tool.
SCENE_SIDE = ("optics/", "core/")
# The twins and the light module they share: folder -> the folders it must not include or link.
TWIN_RULES = {
    "core/render/": ("core/reference/",),
    "core/reference/": ("core/render/",),
    "core/light/": ("core/render/", "core/reference/"),
}
TWIN_TARGET = {"core/render/": re.compile(r"\beikon(::|_)render\b"),
               "core/reference/": re.compile(r"\beikon(::|_)reference\b")}


def twin_hits(rel, no, line, is_source, is_cmake):
    """Crossings between the twins on one line of a file under core/render, core/reference or
    core/light."""
    hits = []
    for folder, forbidden in TWIN_RULES.items():
        if not rel.startswith(folder):
            continue
        m = INCLUDE.match(line) if is_source else None
        for other in forbidden:
            if m and m.group(1).startswith(other):
                hits.append(f"{rel}:{no}: includes <{m.group(1)}> ({folder} must not use {other}; "
                            "shared light code belongs in core/light/)")
            if is_cmake and TWIN_TARGET[other].search(line.split("#", 1)[0]):
                hits.append(f"{rel}:{no}: links the {other} library ({folder} must not; the twins "
                            "are siblings on core/light/)")
    return hits


def files(root):
    try:
        out = subprocess.run(["git", "-C", root, "ls-files", "-z", "--cached", "--others",
                              "--exclude-standard"], capture_output=True, check=True).stdout
        return [p for p in out.decode().split("\0") if p]
    except (OSError, subprocess.CalledProcessError):
        found = []
        for d, dirs, names in os.walk(root):
            dirs[:] = [x for x in dirs if not x.startswith(("build", ".git", "out"))]
            found += [os.path.relpath(os.path.join(d, n), root) for n in names]
        return found


def check(root):
    hits = []
    for rel in sorted(files(root)):
        rel = rel.replace(os.sep, "/")
        path = os.path.join(root, rel)
        if not os.path.isfile(path):
            continue
        scene_side = rel.startswith(SCENE_SIDE)
        is_source = rel.endswith(SOURCE_EXT)
        is_cmake = os.path.basename(rel) == "CMakeLists.txt" or rel.endswith(".cmake")
        if not ((scene_side and is_source) or is_cmake):
            continue
        with open(path, encoding="utf-8", errors="replace") as f:
            lines = f.read().split("\n")
        for no, line in enumerate(lines, 1):
            hits += twin_hits(rel, no, line, is_source, is_cmake)
            if scene_side and is_source:
                m = INCLUDE.match(line)
                if m and m.group(1).startswith(FOREIGN_HEADERS):
                    hits.append(f"{rel}:{no}: includes <{m.group(1)}> (scene side must not use the fitting tool)")
            if is_cmake:
                code = line.split("#", 1)[0]
                if "find_package" in code:
                    continue
                if CERES_OR_YAML.search(code) and not rel.startswith("fitting/"):
                    hits.append(f"{rel}:{no}: links Ceres or yaml-cpp (only fitting/ may)")
                if scene_side and FITTING_TARGET.search(code):
                    hits.append(f"{rel}:{no}: links the fitting library from the scene side")
    return hits


def self_test():
    """A tree with one violation of each kind, and a clean one: the checks must tell them apart."""
    bad = {
        "optics/a.h": '#include "fitting/fitting.h"\n',
        "optics/b.cpp": "#include <ceres/ceres.h>\n",
        "core/scene/c.cpp": "  #  include <yaml-cpp/yaml.h>\n",
        "core/scene/CMakeLists.txt": "target_link_libraries(s PUBLIC eikon::fitting)\n",
        "apps/CMakeLists.txt": "target_link_libraries(e PRIVATE yaml-cpp)\n",
        # The twins crossing (one including the other), and the light module leaning on one.
        "core/render/light_simulator.cpp":
            '#include "core/light/seeding.h"\n#include "core/reference/wavefront.h"\n',
        "core/reference/wavefront.h": '#include "core/render/light_simulator.h"\n',
        "core/render/CMakeLists.txt":
            "target_link_libraries(r PUBLIC eikon::light\n  eikon_reference)\n",
        "core/reference/CMakeLists.txt": "target_link_libraries(c PUBLIC eikon::render)\n",
        "core/light/seeding.cpp": '#include "core/reference/reference_marcher.h"\n',
    }
    # Each defect must be reported at its FILE:LINE.
    bad_at = ["core/render/light_simulator.cpp:2:", "core/reference/wavefront.h:1:",
              "core/render/CMakeLists.txt:2:", "core/reference/CMakeLists.txt:1:",
              "core/light/seeding.cpp:1:"]
    good = {
        "optics/a.h": '#include "optics/uniaxial.h"\n#include <glm/glm.hpp>\n',
        "core/scene/c.cpp": '#include "optics/dispersion.h"\n// fitting/ is not included here\n',
        "fitting/CMakeLists.txt": "target_link_libraries(f PRIVATE Ceres::ceres yaml-cpp)\n",
        "CMakeLists.txt": "find_package(Ceres 2.1 REQUIRED)\nfind_package(yaml-cpp 0.7 REQUIRED)\n",
        "apps/fit.cpp": '#include "fitting/fitting.h"\n',
        "core/render/light_simulator.cpp":
            '#include "core/light/seeding.h"\n// core/reference/wavefront.h: the CPU twin\n',
        "core/render/CMakeLists.txt":
            "target_link_libraries(r PUBLIC eikon::light)  # not eikon::reference\n",
        "core/reference/wavefront.cpp":
            '#include "core/light/seeding.h"\n#include "core/reference/wavefront.h"\n',
        "apps/render.cpp":
            '#include "core/render/light_transport.h"\n#include "core/reference/wavefront.h"\n',
    }
    ok = True
    for tree, expected in ((bad, len(bad)), (good, 0)):
        with tempfile.TemporaryDirectory() as d:
            for rel, text in tree.items():
                os.makedirs(os.path.dirname(os.path.join(d, rel)) or d, exist_ok=True)
                with open(os.path.join(d, rel), "w") as f:
                    f.write(text)
            # Not a git repository: the walk is used, as for an unpacked tarball.
            hits = check(d)
            if len(hits) != expected:
                ok = False
                print(f"self-test: expected {expected} violations, found {len(hits)}: {hits}")
            if tree is bad:
                for at in bad_at:
                    if not any(h.startswith(at) for h in hits):
                        ok = False
                        print(f"self-test: no violation reported at {at}: {hits}")
    print(f"module_boundaries self-test: {int(ok)} passed, {int(not ok)} failed")
    return 0 if ok else 1


def main():
    if len(sys.argv) > 1 and sys.argv[1] == "--self-test":
        return self_test()
    root = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else ".")
    hits = check(root)
    for h in hits:
        print(h)
    print(f"module_boundaries: {1 if not hits else 0} passed, {1 if hits else 0} failed")
    return 1 if hits else 0


if __name__ == "__main__":
    sys.exit(main())
