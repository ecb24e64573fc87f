#!/usr/bin/env bash
# Make `import eikon` work in the `python3` found on PATH too (a pyenv or conda python, say), or
# say clearly why it cannot.
#   scripts/register_path_python.sh [BUILD_DIR]      (default: build; called by scripts/build.sh)
#
# The module is built for /usr/bin/python3 (python/CMakeLists.txt), which install_python.sh
# registers. A `python3` earlier on PATH is another interpreter with its own site-packages:
#  * it imports this build's eikon already (it is /usr/bin/python3, or shares its folders):
#    nothing to do;
#  * its extension suffix is the module's (the same CPython minor version and platform, e.g.
#    .cpython-311-x86_64-linux-gnu.so: the ABI CPython keeps within a minor version): writes
#    eikon.pth, holding BUILD_DIR/python, into its first site-packages folder, checks that it
#    imports eikon from there, and notes when it lacks numpy (eikon's arrays need it;
#    `python3 -m pip install numpy`, or use /usr/bin/python3);
#  * otherwise (another Python version): a note naming /usr/bin/python3 and the rebuild that
#    would serve that python (-DEIKON_PYTHON_EXECUTABLE), and nothing written.
# Never fails the build (exit 0), except for a missing module or build folder (exit 1).
# Testing: EIKON_PATH_PYTHON names the interpreter instead of PATH's python3, EIKON_PTH_DIR the
# folder eikon.pth goes to instead of that interpreter's site-packages.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="$(cd "${1:-$here/build}" 2>/dev/null && pwd)" || {
  echo "eikon: error: build folder ${1:-build} not found" >&2
  exit 1
}
moddir="$build/python"
module="$(ls "$moddir"/eikon.cpython-*.so 2>/dev/null | head -n 1)"
[ -n "$module" ] || { echo "eikon: error: no eikon module in $moddir" >&2; exit 1; }
py="${EIKON_PATH_PYTHON:-$(command -v python3 || true)}"
[ -n "$py" ] || exit 0  # no python3 on PATH: /usr/bin/python3 is the one to use

# Does it import this build's module already (from a neutral folder, PYTHONPATH unset)?
found="$(cd / && env -u PYTHONPATH "$py" -c 'import eikon; print(eikon.__file__)' 2>/dev/null || true)"
case "$found" in "$moddir"/*) exit 0 ;; esac

info="$(cd / && env -u PYTHONPATH "$py" -c 'import site, sys, sysconfig
print(sysconfig.get_config_var("EXT_SUFFIX") or "")
print("%d.%d.%d" % sys.version_info[:3])
print((site.getsitepackages() or [site.getusersitepackages()])[0])' 2>/dev/null)" || {
  echo "eikon: note: $py (python3 on PATH) did not run; use /usr/bin/python3 for eikon" >&2
  exit 0
}
suffix="$(sed -n 1p <<<"$info")"
version="$(sed -n 2p <<<"$info")"
site="${EIKON_PTH_DIR:-$(sed -n 3p <<<"$info")}"
if [ "$(basename "$module")" != "eikon$suffix" ]; then
  echo "eikon: note: python3 on PATH ($py, Python $version) cannot import eikon: the module" \
    "is built for /usr/bin/python3 ($(basename "$module")); run /usr/bin/python3, or rebuild" \
    "for that python with cmake -DEIKON_PYTHON_EXECUTABLE=$py (it needs pybind11's headers" \
    "and numpy there)" >&2
  exit 0
fi
if ! mkdir -p "$site" 2>/dev/null || [ ! -w "$site" ]; then
  echo "eikon: note: python3 on PATH ($py) cannot import eikon and $site is not writable;" \
    "run /usr/bin/python3, or: echo '$moddir' > '$site/eikon.pth'" >&2
  exit 0
fi
tmp="$(mktemp "$site/.eikon.pth.XXXXXX")"
printf '%s\n' "$moddir" >"$tmp"
chmod 0644 "$tmp"
mv -f "$tmp" "$site/eikon.pth"
# The check reads only that folder's .pth files (-S: not the interpreter's other site folders,
# whose eikon.pth may name another build).
found="$(cd / && env -u PYTHONPATH "$py" -S -c 'import site, sys
site.addsitedir(sys.argv[1])
import eikon
print(eikon.__file__)' "$site" 2>&1)" || {
  echo "eikon: note: wrote $site/eikon.pth, but $py still cannot import eikon ($(tail -n 1 <<<"$found"));" \
    "use /usr/bin/python3" >&2
  exit 0
}
echo "eikon: python module registered for $py too: $site/eikon.pth -> $moddir (delete it to undo)"
if ! (cd / && env -u PYTHONPATH "$py" -c 'import numpy' >/dev/null 2>&1); then
  echo "eikon: note: $py has no numpy: import eikon works, but renders and traces return numpy" \
    "arrays; install it there (\"$py\" -m pip install numpy) or use /usr/bin/python3" >&2
fi
exit 0
