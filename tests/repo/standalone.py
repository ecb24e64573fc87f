#!/usr/bin/python3
"""The repository stands alone: no file in it may name the development-aid folder that sits
beside a developer's checkout (users never have it), nor read data from outside the clone.

Scans every file of the source tree (git's tracked files when git is available, else a walk that
skips build folders) for the forbidden names and prints each hit as FILE:LINE.
usage: standalone.py SOURCE_DIR   — prints "standalone: N passed, M failed".
"""
import os
import subprocess
import sys

# Assembled from pieces so that this file does not name them itself.
FORBIDDEN = ["../" + "shared", "/work/" + "shared", "EIKON_" + "SHARED_DIR"]


def files(root):
    try:
        out = subprocess.run(["git", "-C", root, "ls-files", "-z", "--cached", "--others",
                              "--exclude-standard"], capture_output=True, check=True).stdout
        return [os.path.join(root, p) for p in out.decode().split("\0") if p]
    except (OSError, subprocess.CalledProcessError):
        found = []
        for d, dirs, names in os.walk(root):
            dirs[:] = [x for x in dirs if not x.startswith(("build", ".git", "out"))]
            found += [os.path.join(d, n) for n in names]
        return found


def main():
    root = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else ".")
    hits = []
    checked = 0
    for path in files(root):
        if not os.path.isfile(path):
            continue
        try:
            with open(path, "rb") as f:
                data = f.read()
        except OSError:
            continue
        checked += 1
        for no, line in enumerate(data.split(b"\n"), 1):
            for word in FORBIDDEN:
                if word.encode() in line:
                    hits.append(f"{os.path.relpath(path, root)}:{no}: names {word!r}")
    for h in hits:
        print(h)
    print(f"checked {checked} files")
    print(f"standalone: {1 if not hits else 0} passed, {1 if hits else 0} failed")
    return 1 if hits else 0


if __name__ == "__main__":
    sys.exit(main())
