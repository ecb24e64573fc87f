#!/usr/bin/python3
"""Conventions of the repository's text, checked from the sources:

  - history lives in CHANGELOG.md alone: no other text file of the repository (code, tests, docs,
    notebooks, README, scripts, bench, CMake, data) names an "issue N" or a "session N" (in any
    case, plural or with a "#" before the number); the docs and comments say what is true now,
    and CHANGELOG.md says when it came;
  - one π: no C++ file writes π's digits (3.14159…), M_PI or acos(-1) (C++ takes
    std::numbers::pi from <numbers>), and the GLSL kernels define it at most once between them.
    A header under shaders/ is read by both languages: its `#ifdef __cplusplus` part counts as
    C++, its `#else` (or `#ifndef __cplusplus`) part as GLSL.
Text files are the tracked (or new, not ignored) files that decode as UTF-8 and hold no NUL byte.
Each violation is printed as FILE:LINE: what.
usage: conventions.py SOURCE_DIR   — prints "conventions: N failed".
       conventions.py --self-test  — runs the checks on a made-up tree with known defects.
"""
import os
import re
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from repo_checks import report_planted, run_check  # noqa: E402

HISTORY = re.compile(r"\b(issues?|sessions?)\s*#?\s*[0-9]+", re.IGNORECASE)
CHANGELOG = "CHANGELOG.md"
PI = re.compile(r"3\.14159|\bM_PI\b|\bacos\s*\(\s*-\s*1(\.0*)?\s*\)")
CXX = (".cpp", ".cc", ".cxx", ".h", ".hpp")
GLSL = (".glsl", ".comp", ".vert", ".frag")


def tracked(root):
    out = subprocess.run(["git", "-C", root, "ls-files", "-z", "--cached", "--others",
                          "--exclude-standard"], capture_output=True, check=True).stdout
    return sorted(p for p in out.decode().split("\0")
                  if p and os.path.isfile(os.path.join(root, p)))


def text_of(root, rel):
    with open(os.path.join(root, rel), "rb") as f:
        data = f.read()
    if b"\0" in data:
        return None
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError:
        return None


def history(rel, lines):
    if rel == CHANGELOG:
        return []
    hits = []
    for no, line in enumerate(lines, 1):
        m = HISTORY.search(line)
        if m:
            hits.append(f"{rel}:{no}: '{m.group(0)}' is history: say what is true now "
                        f"(dates and issue numbers belong in {CHANGELOG})")
    return hits


def languages(rel, lines):
    """For each line, (is C++, is GLSL). A shared header under shaders/ is split on __cplusplus."""
    if rel.endswith(GLSL):
        return [(False, True)] * len(lines)
    if not rel.endswith(CXX):
        return [(False, False)] * len(lines)
    if not rel.startswith("shaders/"):
        return [(True, False)] * len(lines)
    out, stack = [], []  # stack of "cpp", "glsl" or "both" per open #if
    for line in lines:
        d = line.strip()
        if re.match(r"#\s*ifdef\s+__cplusplus\b", d) or re.match(r"#\s*if\s+defined\s*\(?\s*__cplusplus", d):
            stack.append("cpp")
        elif re.match(r"#\s*ifndef\s+__cplusplus\b", d) or re.match(r"#\s*if\s+!\s*defined\s*\(?\s*__cplusplus", d):
            stack.append("glsl")
        elif re.match(r"#\s*if", d):
            stack.append("both")
        elif re.match(r"#\s*else\b", d) and stack:
            stack[-1] = {"cpp": "glsl", "glsl": "cpp"}.get(stack[-1], stack[-1])
        elif re.match(r"#\s*endif\b", d) and stack:
            stack.pop()
        out.append(("glsl" not in stack, "cpp" not in stack))
    return out


def one_pi(texts):
    hits, glsl_defs = [], []
    for rel, lines in texts:
        for no, (line, (cxx, glsl)) in enumerate(zip(lines, languages(rel, lines)), 1):
            code = line.split("//")[0]
            if not PI.search(code):
                continue
            if cxx:
                hits.append(f"{rel}:{no}: π defined in C++: use std::numbers::pi (<numbers>)")
            if glsl:
                glsl_defs.append(f"{rel}:{no}")
    for where in glsl_defs[1:]:
        hits.append(f"{where}: a second GLSL definition of π (the first: {glsl_defs[0]}); "
                    "the kernels share one")
    return hits


def check(root):
    texts = []
    for rel in tracked(root):
        t = text_of(root, rel.replace("/", os.sep))
        if t is not None:
            texts.append((rel.replace(os.sep, "/"), t.splitlines()))
    hits = []
    for rel, lines in texts:
        hits += history(rel, lines)
    return hits + one_pi(texts)


def self_test():
    i, s = "iss" + "ue", "sess" + "ion"  # spelt apart, so that this file passes its own check
    with tempfile.TemporaryDirectory() as root:
        def write(rel, text):
            os.makedirs(os.path.join(root, os.path.dirname(rel)), exist_ok=True)
            with open(os.path.join(root, rel), "w", encoding="utf-8") as f:
                f.write(text)
        write(CHANGELOG, f"# Changelog\n- Sharp interfaces ({i} 13, {s} 14).\n")
        write("core/a.cpp", f"// The march ({i} 13): straight segments.\nint a() {{ return 1; }}\n")
        write("docs/b.md", f"# B\n\nMeasured in {s} 14, as {i.title()}s #4 and 5 asked.\n")
        write("notebooks/c.ipynb", '{"cells": [{"source": ["see ' + i + 's 4 and 5"]}]}\n')
        write("CMakeLists.txt", f"# the tests of {i.title()} 7\nproject(x)\n")
        write("core/clean.cpp", "// A Session serves both twins; 14 sessions ago means nothing.\n"
                                "#include <numbers>\ndouble c() { return std::numbers::pi; }\n")
        write("core/pi.cpp", "constexpr double kPi = 3.14159265358979323846;\n")
        write("tests/d_test.cpp", "double d() { return M_PI / 2; }\n")
        write("anisotropic/e.h", "inline double e() { return std::acos(-1.0); }\n")
        write("shaders/shared.h", "#ifdef __cplusplus\nnamespace x {}\n#else\n"
                                  "const float kPi = 3.14159265358979323846;\n#endif\n")
        write("shaders/march.glsl", "const float kPi = 3.14159265;\n")
        write("shaders/note.glsl", "// pi is 3.14159 (a comment, not a definition)\n")
        with open(os.path.join(root, "image.bin"), "wb") as f:
            f.write(i.encode() + b" 9\0\x89PNG")
        subprocess.run(["git", "init", "-q", root], check=True)
        hits = check(root)
        expected = [("core/a.cpp:1:", f"'{i} 13' is history"),
                    ("docs/b.md:3:", f"'{s} 14' is history"),
                    ("notebooks/c.ipynb:1:", f"'{i}s 4' is history"),
                    ("CMakeLists.txt:1:", f"'{i.title()} 7' is history"),
                    ("core/pi.cpp:1:", "π defined in C++"),
                    ("tests/d_test.cpp:1:", "π defined in C++"),
                    ("anisotropic/e.h:1:", "π defined in C++"),
                    ("shaders/shared.h:4:", "a second GLSL definition of π (the first: "
                                            "shaders/march.glsl:1)")]

        return report_planted("conventions", expected, hits)


def main():
    return run_check("conventions", check, self_test, __doc__)


if __name__ == "__main__":
    sys.exit(main())
