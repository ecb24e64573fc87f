#!/usr/bin/python3
"""The repository's shape, checked from the sources (docs/architecture.md):

  - tests/ mirrors the source tree: every folder under tests/ (but data/, repo/ and python/, the
    Python module's tests) names a source folder at the same path (tests/core/render ↔ core/render),
    and no test source sits loose in tests/core/ (only shared helpers, *.h, live there);
  - no function in core/, anisotropic/, fitting/, python/ or apps/ is longer than MAX_LINES lines
    (counted by Universal Ctags from its first to its last line, lambdas included), so the marches,
    the simulators and the commands stay split into named stages (the ones docs/twins.md pairs);
  - every C++ file is formatted with the project's .clang-format (clang-format --dry-run).
Each violation is printed as FILE:LINE: what.
usage: layout.py SOURCE_DIR   — prints "layout: N checks, M failed".
       layout.py --self-test  — runs the checks on a made-up tree with known defects.
"""
import os
import shutil
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from repo_checks import report_planted, run_check  # noqa: E402

MAX_LINES = 120
LENGTH_CHECKED = ("core/", "anisotropic/", "fitting/", "python/", "apps/")
NOT_MIRRORED = ("tests/data", "tests/repo", "tests/python")
CXX = (".cpp", ".h")


def tracked(root):
    out = subprocess.run(["git", "-C", root, "ls-files", "-z", "--cached", "--others",
                          "--exclude-standard"], capture_output=True, check=True).stdout
    return [p for p in out.decode().split("\0") if p and os.path.isfile(os.path.join(root, p))]


def mirror(root, files):
    hits = []
    folders = sorted({os.path.dirname(p) for p in files if p.startswith("tests/")})
    for d in folders:
        if d == "tests" or d.startswith(NOT_MIRRORED):
            continue
        source = d[len("tests/"):]
        if not os.path.isdir(os.path.join(root, source)):
            first = next(p for p in files if os.path.dirname(p) == d)
            hits.append(f"{first}:1: tests/{source} mirrors no source folder {source}/")
    for p in files:
        if os.path.dirname(p) == "tests/core" and p.endswith(".cpp"):
            hits.append(f"{p}:1: a test source loose in tests/core/; it belongs in the subfolder "
                        "of the core/ module it tests")
    return hits


def lengths(root, files):
    sources = [p for p in files if p.startswith(LENGTH_CHECKED) and p.endswith(CXX)]
    if not sources:
        return []
    if shutil.which("ctags") is None:
        return ["ctags:1: Universal Ctags is not installed (scripts/install_deps.sh installs it)"]
    out = subprocess.run(["ctags", "--c++-kinds=f", "--fields=+ne", "--language-force=C++",
                          "-o", "-"] + sources, cwd=root, capture_output=True, text=True,
                         check=True).stdout
    hits = []
    for row in out.splitlines():
        cols = row.split("\t")
        fields = dict(c.split(":", 1) for c in cols[3:] if ":" in c)
        if "line" in fields and "end" in fields:
            n = int(fields["end"]) - int(fields["line"]) + 1
            if n > MAX_LINES:
                name = cols[0] if not cols[0].startswith("__anon") else "a lambda"
                hits.append(f"{cols[1]}:{fields['line']}: {name} is {n} lines "
                            f"(at most {MAX_LINES}: split it into named stages)")
    return hits


def formatting(root, files):
    sources = [p for p in files if p.endswith(CXX) and not p.startswith("tests/data/")]
    if not sources:
        return []
    if shutil.which("clang-format") is None:
        return ["clang-format:1: clang-format is not installed (scripts/install_deps.sh installs it)"]
    hits = []
    for i in range(0, len(sources), 200):
        r = subprocess.run(["clang-format", "--dry-run", "--Werror"] + sources[i:i + 200],
                           cwd=root, capture_output=True, text=True)
        seen = set()
        for line in r.stderr.splitlines():
            if ": error:" in line:
                where = line.split(": error:")[0]
                f = where.split(":")[0]
                if f not in seen:  # one line per file: the first place it differs
                    seen.add(f)
                    hits.append(f"{os.path.relpath(where, root) if os.path.isabs(where) else where}"
                                ": not formatted (run clang-format -i on it)")
    return hits


def check(root):
    files = sorted(p.replace(os.sep, "/") for p in tracked(root))
    return mirror(root, files) + lengths(root, files) + formatting(root, files)


def self_test():
    with tempfile.TemporaryDirectory() as root:
        def write(rel, text):
            os.makedirs(os.path.join(root, os.path.dirname(rel)), exist_ok=True)
            with open(os.path.join(root, rel), "w") as f:
                f.write(text)
        shutil.copy(os.path.join(os.path.dirname(__file__), "..", "..", ".clang-format"),
                    os.path.join(root, ".clang-format"))
        body = "".join(f"  x += {i};\n" for i in range(MAX_LINES))
        write("core/render/long.cpp", "int longOne(int x) {\n" + body + "  return x;\n}\n")
        write("core/render/short.cpp", "int shortOne(int x) { return x; }\n")
        write("apps/long_command.cpp", "int longCommand(int x) {\n" + body + "  return x;\n}\n")
        write("tests/core/render/short_test.cpp", "int shortTest() { return 1; }\n")
        write("tests/core/loose_test.cpp", "int looseTest() { return 1; }\n")
        write("tests/core/nowhere/nowhere_test.cpp", "int nowhereTest() { return 1; }\n")
        write("anisotropic/ugly.h", "int  ugly( int x ){return x;}\n")
        subprocess.run(["git", "init", "-q", root], check=True)
        hits = check(root)
        expected = [("core/render/long.cpp:1:", "longOne is 123 lines"),
                    ("apps/long_command.cpp:1:", "longCommand is 123 lines"),
                    ("tests/core/loose_test.cpp:1:", "a test source loose"),
                    ("tests/core/nowhere/nowhere_test.cpp:1:", "mirrors no source folder"),
                    ("anisotropic/ugly.h:1:", "not formatted")]

        return report_planted("layout", expected, hits)


def main():
    return run_check("layout", check, self_test, __doc__)


if __name__ == "__main__":
    sys.exit(main())
