#!/usr/bin/python3
"""Runs every `eikon ...` command shown in the README, as a user would copy it, so the README
cannot rot.

A command is a line `$ eikon ...` or `$ build/apps/eikon ...` inside a fenced code block; the
lines after it, up to the next `$` line or the end of the block, are its printed output. For each
command this checks that
  * it exits 0, or non-zero when its shown output contains `eikon: error:`;
  * every shown output line appears in what it printed, in order; `...` in a shown line matches
    anything (the README elides columns that way), and numbers agree to 1e-4 relative (1e-5
    absolute), so another GPU's float32 rounding passes while a changed result fails.
Commands run in a scratch folder holding links to the clone's scenes/, materials/, tests/ and
docs/, so relative paths work and outputs land in the scratch folder. `render` commands get a
small image (`--width 48 --height 36 --spp 1`, replacing any size the line gives): the README's
pictures are made at full size by hand, this only checks that the command runs.

usage: readme_commands.py EIKON_BINARY SOURCE_DIR
Prints "readme: N passed, M failed" and exits non-zero if any failed.
"""
import os
import re
import shlex
import subprocess
import sys
import tempfile

SMALL_RENDER = ["--width", "48", "--height", "36", "--spp", "1"]


def commands(readme_text):
    """Yields (line_no, argv_after_eikon, expected_lines) for each `$ eikon` line in a code block."""
    in_block = False
    current = None
    for no, line in enumerate(readme_text.splitlines(), 1):
        if line.lstrip().startswith("```"):
            if in_block and current:
                yield current
            current = None
            in_block = not in_block
            continue
        if not in_block:
            continue
        m = re.match(r"^\$ (?:build/apps/)?eikon(\s.*)?$", line)
        if m:
            if current:
                yield current
            current = (no, shlex.split(m.group(1) or ""), [])
        elif line.startswith("$ "):
            if current:
                yield current
            current = None  # another program (./setup.sh ...): not ours to run here
        elif current is not None and line.strip():
            current[2].append(line.rstrip())
    if current:
        yield current


NUMBER = re.compile(r"[-+]?(?:\d+\.\d*|\.\d+|\d+)(?:[eE][-+]?\d+)?")


def line_pattern(expected):
    """A regex for one shown line: `...` matches anything, and every number is captured so that
    it can be compared with a tolerance (another GPU rounds float32 differently in the last
    digits; the CPU-side numbers agree exactly)."""
    def literal(text):
        out, at = "", 0
        for m in NUMBER.finditer(text):
            out += re.escape(text[at:m.start()]) + "(" + NUMBER.pattern + ")"
            at = m.end()
        return out + re.escape(text[at:])
    parts = [literal(p.strip()) for p in expected.split("...")]
    return re.compile(r"\s*" + r".*?".join(parts) + r"\s*$")


def numbers_agree(expected, match):
    want = [float(x) for x in NUMBER.findall(" ".join(p.strip() for p in expected.split("...")))]
    got = [float(x) for x in match.groups()]
    return len(want) == len(got) and all(
        abs(w - g) <= 1e-5 + 1e-4 * abs(w) for w, g in zip(want, got))


def check(binary, scratch, no, args, expected):
    argv = list(args)
    if argv and argv[0] == "render":
        for flag in ("--width", "--height", "--spp"):
            while flag in argv:
                i = argv.index(flag)
                del argv[i:i + 2]
        argv += SMALL_RENDER
    proc = subprocess.run([binary] + argv, cwd=scratch, capture_output=True, text=True,
                          timeout=900, env=dict(os.environ, EIKON_CACHE_DIR=os.path.join(scratch, "cache")))
    printed = (proc.stdout + proc.stderr).splitlines()
    problems = []
    wants_error = any(e.lstrip().startswith("eikon: error:") for e in expected)
    if wants_error and proc.returncode == 0:
        problems.append("exited 0 but the README shows an error")
    if not wants_error and proc.returncode != 0:
        problems.append(f"exited {proc.returncode}")
    at = 0
    for e in expected:
        pat = line_pattern(e)
        for i in range(at, len(printed)):
            m = pat.match(printed[i])
            if m and numbers_agree(e, m):
                at = i + 1
                break
        else:
            problems.append(f"README line not printed (in order): {e!r}")
    name = f"README.md:{no}: eikon {' '.join(args)}"
    if problems:
        print(f"FAIL {name}")
        for p in problems:
            print(f"    {p}")
        print("    printed:\n" + "\n".join("      | " + l for l in printed[-40:]))
        return False
    print(f"PASS {name}")
    return True


def main():
    if len(sys.argv) != 3:
        print(__doc__.strip().splitlines()[-2], file=sys.stderr)
        return 2
    binary, source = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
    with open(os.path.join(source, "README.md"), encoding="utf-8") as f:
        cmds = list(commands(f.read()))
    if not cmds:
        print("readme: no `$ eikon` commands found in README.md")
        return 1
    passed = failed = 0
    with tempfile.TemporaryDirectory(prefix="eikon-readme-") as scratch:
        for d in ("scenes", "materials", "tests", "docs"):
            os.symlink(os.path.join(source, d), os.path.join(scratch, d))
        os.mkdir(os.path.join(scratch, "build"))
        os.makedirs(os.path.join(scratch, "build", "apps"))
        os.symlink(binary, os.path.join(scratch, "build", "apps", "eikon"))
        for no, args, expected in cmds:
            if check(binary, scratch, no, args, expected):
                passed += 1
            else:
                failed += 1
    print(f"readme: {passed} passed, {failed} failed")
    return 0 if failed == 0 else 1


if __name__ == "__main__":
    sys.exit(main())
