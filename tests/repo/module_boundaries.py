#!/usr/bin/python3
"""Module boundaries: every arrow of docs/architecture.md's table, checked from the sources so
that a static-library chain cannot hide a dependency.

For each module folder (one CMake library, or a front end) the table gives the project targets it
links; from that:
  - its sources (.h, .cpp, ...) may include headers of its own folder and of every module it
    reaches along the arrows (the links and theirs: a PUBLIC chain hands them on), and of no other
    project folder (apps/, python/, bench/, fuzz/, tests/ or a module not below it);
  - the front ends apps/ and python/ go through one door: they may include core/session/ (which
    forwards what they need of the layers under it), fitting/ (`eikon fit`, Python's fits) and the
    data layers a front end hands the session or shows: core/scene/ and core/io/ (and, for
    python/, anisotropic/: the module exposes pure optics formulas); not core/render, core/vk,
    core/light, core/volume, core/reference or core/spectrum;
  - its CMakeLists.txt links (eikon::NAME or eikon_NAME) only the targets its row names;
  - and, for the libraries the fitting tool keeps to itself: no file under anisotropic/ or core/
    includes a Ceres, glog, Eigen or yaml-cpp header, and no CMakeLists.txt outside fitting/ links
    Ceres::ceres or yaml-cpp.
Each violation is printed as FILE:LINE: what.
usage: module_boundaries.py SOURCE_DIR   — prints "module_boundaries: N passed, M failed".
       module_boundaries.py --self-test  — runs the checks on made-up trees with known defects.
"""
import os
import re
import subprocess
import sys
import tempfile

INCLUDE = re.compile(r'^\s*#\s*include\s*[<"]([^">]+)[">]')
SOURCE_EXT = (".h", ".hpp", ".cpp", ".cc", ".inl")
FOREIGN_HEADERS = ("ceres/", "glog/", "Eigen/", "yaml-cpp/")
CERES_OR_YAML = re.compile(r"\bCeres::\w+|\byaml-cpp\b")
# Folders that must stay free of the fitting tool's libraries.
SCENE_SIDE = ("anisotropic/", "core/")

# docs/architecture.md's table: module folder -> (its CMake target eikon::NAME, or None for a front
# end, and the project targets it links, PUBLIC or PRIVATE).
MODULES = {
    "anisotropic/": ("anisotropic", ()),
    "fitting/": ("fitting", ("anisotropic", "io")),
    "core/spectrum/": ("spectrum", ()),
    "core/io/": ("io", ()),
    "core/vk/": ("vk", ("io",)),
    "shaders/": ("shaders", ()),
    "core/scene/": ("scene", ("anisotropic", "io", "spectrum")),
    "core/volume/": ("volume", ("scene", "io")),
    "core/contract/": ("contract", ("scene", "spectrum")),
    "core/light/": ("light", ("volume", "spectrum", "io")),
    "core/reference/": ("reference", ("contract", "light", "volume")),
    "core/render/": ("render", ("contract", "light", "volume", "vk", "shaders")),
    "core/session/": ("session", ("contract", "render", "reference", "light", "volume", "scene")),
    "apps/": (None, ("session", "fitting")),
    "python/": (None, ("session", "fitting")),
}
# The front ends' door: the folders they may include, instead of all the session reaches.
DOOR = {
    "apps/": ("core/session/", "fitting/", "core/scene/", "core/io/"),
    "python/": ("core/session/", "fitting/", "core/scene/", "core/io/", "anisotropic/"),
}
# Project folders that are no module: nothing under a module may include them.
NON_MODULES = ("bench/", "fuzz/", "tests/")
FOLDER_OF = {target: folder for folder, (target, _) in MODULES.items() if target}
PROJECT_TARGET = re.compile(r"\beikon(?:::|_)(" + "|".join(sorted(FOLDER_OF)) + r")\b")
# Why some arrows are absent, said with the violation (docs/design.md §1).
WHY = {
    ("core/render/", "core/reference/"): "the twins are siblings on core/light/; shared light "
                                         "code belongs in core/light/",
    ("core/reference/", "core/render/"): "the twins are siblings on core/light/; shared light "
                                         "code belongs in core/light/",
    ("core/light/", "core/render/"): "core/light/ stands under both twins",
    ("core/light/", "core/reference/"): "core/light/ stands under both twins",
}


def reach(folder):
    """The module folders `folder` reaches along the table's arrows (itself included)."""
    seen, todo = {folder}, [folder]
    while todo:
        for target in MODULES[todo.pop()][1]:
            below = FOLDER_OF[target]
            if below not in seen:
                seen.add(below)
                todo.append(below)
    return seen


def allowed_includes(folder):
    if folder in DOOR:
        return {folder, *DOOR[folder]}
    return reach(folder)


ALLOWED = {folder: allowed_includes(folder) for folder in MODULES}


def module_of(rel):
    return next((m for m in MODULES if rel.startswith(m)), None)


def project_folder(header):
    """The project folder a header path names ("core/vk/" for "core/vk/context.h"), or None."""
    parts = header.split("/")
    if len(parts) < 2:
        return None
    if parts[0] == "core":
        return "core/" + parts[1] + "/" if len(parts) > 2 else None
    folder = parts[0] + "/"
    return folder if folder in MODULES or folder in NON_MODULES else None


def why(module, other):
    if (module, other) in WHY:
        return WHY[(module, other)]
    if module in DOOR:
        return "a front end goes through core/session/, which forwards what it needs"
    return "docs/architecture.md draws no arrow there"


def include_hits(rel, module, no, line):
    m = INCLUDE.match(line)
    if not m:
        return []
    header, hits = m.group(1), []
    other = project_folder(header)
    if module and other and other not in ALLOWED[module]:
        hits.append(f"{rel}:{no}: includes <{header}> ({module} may include only "
                    f"{', '.join(sorted(ALLOWED[module]))}; {why(module, other)})")
    if rel.startswith(SCENE_SIDE) and header.startswith(FOREIGN_HEADERS):
        hits.append(f"{rel}:{no}: includes <{header}> (only fitting/ uses Ceres and yaml-cpp)")
    return hits


def cmake_hits(rel, module, no, line):
    code = line.split("#", 1)[0]
    if "find_package" in code:
        return []
    hits = []
    if CERES_OR_YAML.search(code) and not rel.startswith("fitting/"):
        hits.append(f"{rel}:{no}: links Ceres or yaml-cpp (only fitting/ may)")
    if module:
        own, links = MODULES[module]
        for target in PROJECT_TARGET.findall(code):
            if target != own and target not in links:
                hits.append(f"{rel}:{no}: links eikon::{target} ({module} links only "
                            f"{', '.join(links) or 'no project target'}; "
                            f"{why(module, FOLDER_OF[target])})")
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
        module = module_of(rel)
        is_source = rel.endswith(SOURCE_EXT) and (module or rel.startswith(SCENE_SIDE))
        is_cmake = os.path.basename(rel) == "CMakeLists.txt" or rel.endswith(".cmake")
        if not (is_source or is_cmake) or not os.path.isfile(path):
            continue
        with open(path, encoding="utf-8", errors="replace") as f:
            lines = f.read().split("\n")
        for no, line in enumerate(lines, 1):
            if is_source:
                hits += include_hits(rel, module, no, line)
            if is_cmake:
                hits += cmake_hits(rel, module, no, line)
    return hits


def run_on(tree):
    with tempfile.TemporaryDirectory() as d:
        for rel, text in tree.items():
            os.makedirs(os.path.dirname(os.path.join(d, rel)) or d, exist_ok=True)
            with open(os.path.join(d, rel), "w") as f:
                f.write(text)
        return check(d)  # not a git repository: the walk is used, as for an unpacked tarball


def planted_trees():
    """Every rule planted: for each module, one include of each project folder it may not use and
    one link of each project target it may not link (one per line, so each is found at its
    FILE:LINE), and a clean tree using everything each module may use."""
    folders = sorted(set(MODULES) | set(NON_MODULES) | {"core/session/"})
    bad, good, bad_at = {}, {}, []
    for module, (own, links) in MODULES.items():
        forbidden = [f for f in folders if f not in ALLOWED[module]]
        bad[module + "planted.cpp"] = "".join(f'#include "{f}x.h"\n' for f in forbidden)
        bad_at += [f"{module}planted.cpp:{i + 1}:" for i in range(len(forbidden))]
        good[module + "planted.cpp"] = "".join(f'#include "{f}x.h"\n'
                                               for f in sorted(ALLOWED[module]))
        unlinkable = [t for t in sorted(FOLDER_OF) if t != own and t not in links]
        bad[module + "CMakeLists.txt"] = "".join(f"target_link_libraries(t PRIVATE eikon::{t})\n"
                                                 for t in unlinkable)
        bad_at += [f"{module}CMakeLists.txt:{i + 1}:" for i in range(len(unlinkable))]
        good[module + "CMakeLists.txt"] = (f"target_link_libraries(t PUBLIC "
                                           f"{' '.join('eikon::' + t for t in links)} "
                                           "PRIVATE eikon::warnings)\n")
    return bad, bad_at, good


def self_test():
    """Made-up trees with known defects, and clean ones: the checks must tell them apart."""
    bad = {
        "anisotropic/a.h": '#include "fitting/fitting.h"\n',
        "anisotropic/b.cpp": "#include <ceres/ceres.h>\n",
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
        # The front ends past their door, the fitting tool on a scene header, a layer upwards.
        "apps/render.cpp": '#include "core/session/session.h"\n#include "core/vk/timings.h"\n',
        "python/analytic.cpp": '#include "anisotropic/fresnel.h"\n'
                               '#include "core/reference/reference_marcher.h"\n',
        "python/CMakeLists.txt": "target_link_libraries(p PRIVATE eikon::session\n"
                                 "  eikon::render)\n",
        "fitting/index_data.h": '#include "anisotropic/index_limits.h"\n#include "core/scene/limits.h"\n',
        "core/volume/voxelizer.cpp": '#include "core/scene/scene.h"\n#include "apps/commands.h"\n',
        "core/session/session.cpp": '#include "core/render/view_renderer.h"\n'
                                    '#include "tests/core/session/x.h"\n',
    }
    # Each defect must be reported at its FILE:LINE (the first line where the file has two).
    bad_at = ["core/render/light_simulator.cpp:2:", "core/reference/wavefront.h:1:",
              "core/render/CMakeLists.txt:2:", "core/reference/CMakeLists.txt:1:",
              "core/light/seeding.cpp:1:", "apps/render.cpp:2:", "python/analytic.cpp:2:",
              "python/CMakeLists.txt:2:", "fitting/index_data.h:2:", "core/volume/voxelizer.cpp:2:",
              "core/session/session.cpp:2:"]
    good = {
        "anisotropic/a.h": '#include "anisotropic/uniaxial.h"\n#include <glm/glm.hpp>\n',
        "core/scene/c.cpp": '#include "anisotropic/dispersion.h"\n// fitting/ is not included here\n',
        "fitting/CMakeLists.txt":
            "target_link_libraries(eikon_fitting PUBLIC eikon::anisotropic PRIVATE eikon::io "
            "Ceres::ceres yaml-cpp)\n",
        "CMakeLists.txt": "find_package(Ceres 2.1 REQUIRED)\nfind_package(yaml-cpp 0.7 REQUIRED)\n",
        "apps/fit.cpp": '#include "fitting/fitting.h"\n#include "core/io/atomic_write.h"\n',
        "core/render/light_simulator.cpp":
            '#include "core/light/seeding.h"\n// core/reference/wavefront.h: the CPU twin\n'
            '#include "shaders/eikon_shared.h"\n#include "core/scene/scene.h"\n',
        "core/render/CMakeLists.txt":
            "target_link_libraries(r PUBLIC eikon::light)  # not eikon::reference\n"
            "add_dependencies(eikon_render eikon_shaders_spv)\n",
        "core/reference/wavefront.cpp":
            '#include "core/light/seeding.h"\n#include "core/reference/wavefront.h"\n',
        "apps/render.cpp":
            '#include "core/session/front_end.h"\n#include "core/scene/scene.h"\n'
            '#include "apps/commands.h"\n#include <GLFW/glfw3.h>\n',
        "python/module.cpp": '#include "anisotropic/fresnel.h"\n#include "python/module.h"\n',
        "core/session/session.cpp": '#include "core/render/view_renderer.h"\n'
                                    '#include "core/vk/context.h"\n',
        "bench/march_bench.cpp": '#include "core/render/view_renderer.h"\n',
    }
    planted_bad, planted_at, planted_good = planted_trees()
    ok = True
    for tree, expected, at in ((bad, len(bad), bad_at), (good, 0, []),
                               (planted_bad, len(planted_at), planted_at),
                               (planted_good, 0, [])):
        hits = run_on(tree)
        if len(hits) != expected:
            ok = False
            print(f"self-test: expected {expected} violations, found {len(hits)}: {hits}")
        for a in at:
            if not any(h.startswith(a) for h in hits):
                ok = False
                print(f"self-test: no violation reported at {a}: {hits}")
    print(f"module_boundaries self-test: {len(MODULES)} modules, {len(planted_at)} forbidden "
          f"arrows planted; {int(ok)} passed, {int(not ok)} failed")
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
