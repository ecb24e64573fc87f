#!/usr/bin/env bash
# Make `import eikon` work in Debian's /usr/bin/python3 from any folder, without PYTHONPATH.
#   scripts/install_python.sh [BUILD_DIR]          (default: build; called by scripts/build.sh)
#
# What it does, exactly: writes ONE file, eikon.pth, into the first site-packages folder of
# /usr/bin/python3 (on Debian 12: /usr/local/lib/python3.11/dist-packages/, the folder Debian keeps
# for locally installed modules; created if missing). The file holds one line, the absolute path of
# BUILD_DIR/python, which Python's `site` module appends to sys.path at start-up, so the module
# built there (eikon.cpython-*.so, target eikon_python) is found — and a rebuild is picked up
# without installing again. Nothing is copied and no other file is touched; running it again
# replaces the line (the last build installed wins). Undo: delete that eikon.pth.
#
# Needs write access to that folder (root, as setup.sh and test.sh run on Debian); without it,
# prints the line to run as root instead and exits 1. Checks the result by importing eikon with
# /usr/bin/python3 from / with PYTHONPATH unset, and prints where the module was found.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${1:-$here/build}"
py=/usr/bin/python3
[ -x "$py" ] || { echo "eikon: error: $py not found (Debian's python3 package)" >&2; exit 1; }
build="$(cd "$build" 2>/dev/null && pwd)" || { echo "eikon: error: build folder ${1:-build} not found" >&2; exit 1; }
moddir="$build/python"
if ! ls "$moddir"/eikon.cpython-*.so >/dev/null 2>&1; then
  echo "eikon: error: no eikon module in $moddir (build the eikon_python target first)" >&2
  exit 1
fi
site="$(cd / && env -u PYTHONPATH "$py" -c 'import site; print(site.getsitepackages()[0])')"
pth="$site/eikon.pth"
if ! mkdir -p "$site" 2>/dev/null || [ ! -w "$site" ]; then
  echo "eikon: error: cannot write $site; run as root: echo '$moddir' > '$pth'" >&2
  exit 1
fi
tmp="$(mktemp "$site/.eikon.pth.XXXXXX")"
printf '%s\n' "$moddir" >"$tmp"
chmod 0644 "$tmp"
mv -f "$tmp" "$pth"
found="$(cd / && env -u PYTHONPATH "$py" -c 'import eikon; print(eikon.__file__)')" || {
  echo "eikon: error: wrote $pth, but /usr/bin/python3 still cannot import eikon" >&2
  exit 1
}
case "$found" in
  "$moddir"/*) ;;
  *) echo "eikon: error: wrote $pth, but /usr/bin/python3 imports another eikon: $found" >&2; exit 1 ;;
esac
echo "eikon: python module registered: $pth -> $moddir (import eikon finds $found)"
