#!/usr/bin/env bash
# Make `import eikon` work in Debian's /usr/bin/python3 from any folder, without PYTHONPATH.
#   scripts/install_python.sh [--site DIR] [BUILD_DIR]   (default: build; called by scripts/build.sh)
#
# What it does, exactly: writes ONE file, eikon.pth, into a site folder. By default that is the
# first site-packages folder of /usr/bin/python3 (on Debian 12: /usr/local/lib/python3.11/dist-packages/,
# the folder Debian keeps for locally installed modules; created if missing). The file holds one
# line, the absolute path of BUILD_DIR/python, which Python's `site` module appends to sys.path at
# start-up, so the module built there (eikon.cpython-*.so, target eikon_python) is found — and a
# rebuild is picked up without installing again. Nothing is copied and no other file is touched;
# running it again replaces the line (the last build installed wins). Undo: delete that eikon.pth.
#
# --site DIR (or EIKON_PYTHON_SITE=DIR) writes eikon.pth into DIR instead (created if missing),
# touching nothing of the system's: a folder the interpreter reads .pth files from only when told,
# with site.addsitedir(DIR). The CTest test python.install_module installs into the build tree so.
#
# The new eikon.pth is checked before it replaces anything: /usr/bin/python3, run from / with
# PYTHONPATH unset, must import eikon from BUILD_DIR/python through it (site.addsitedir of a
# scratch folder holding it, its folder first); a failed check leaves any eikon.pth there as it was. The default
# folder needs write access (root, as setup.sh and test.sh run on Debian); without it, prints the
# line to run as root instead and exits 1. Prints where the module was found.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
site="${EIKON_PYTHON_SITE:-}"
args=()
while [ $# -gt 0 ]; do
  case "$1" in
    --site) [ $# -ge 2 ] || { echo "eikon: error: --site needs a folder" >&2; exit 2; }; site="$2"; shift 2 ;;
    --site=*) site="${1#--site=}"; shift ;;
    -h|--help) sed -n '2,3p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) args+=("$1"); shift ;;
  esac
done
[ ${#args[@]} -le 1 ] || { echo "eikon: error: one BUILD_DIR at most, got ${args[*]}" >&2; exit 2; }
py=/usr/bin/python3
[ -x "$py" ] || { echo "eikon: error: $py not found (Debian's python3 package)" >&2; exit 1; }
given="${args[0]:-$here/build}"
build="$(cd "$given" 2>/dev/null && pwd)" || { echo "eikon: error: build folder $given not found" >&2; exit 1; }
moddir="$build/python"
if ! ls "$moddir"/eikon.cpython-*.so >/dev/null 2>&1; then
  echo "eikon: error: no eikon module in $moddir (build the eikon_python target first)" >&2
  exit 1
fi
# Imports eikon with the .pth files of folder $1 added (site.addsitedir, its folders put first so
# that an eikon.pth of the system's cannot answer instead), from /, PYTHONPATH unset; prints the
# module's file.
import_via() {
  (cd / && env -u PYTHONPATH "$py" -c '
import site, sys
before = list(sys.path)
site.addsitedir(sys.argv[1])
sys.path[:] = [p for p in sys.path if p not in before] + before
import eikon
print(eikon.__file__)' "$1")
}
if [ -z "$site" ]; then
  site="$(cd / && env -u PYTHONPATH "$py" -c 'import site; print(site.getsitepackages()[0])')"
  system=1
else
  mkdir -p "$site" && site="$(cd "$site" && pwd)" || { echo "eikon: error: cannot create $site" >&2; exit 1; }
  system=0
fi
pth="$site/eikon.pth"
if ! mkdir -p "$site" 2>/dev/null || [ ! -w "$site" ]; then
  echo "eikon: error: cannot write $site; run as root: echo '$moddir' > '$pth'" >&2
  exit 1
fi
# The new file, checked in a scratch folder of its own before it replaces anything.
scratch="$(mktemp -d)"
trap 'rm -rf "$scratch"' EXIT
printf '%s\n' "$moddir" >"$scratch/eikon.pth"
found="$(import_via "$scratch")" || {
  echo "eikon: error: /usr/bin/python3 cannot import eikon from $moddir; $pth left as it was" >&2
  exit 1
}
case "$found" in
  "$moddir"/*) ;;
  *) echo "eikon: error: /usr/bin/python3 imports another eikon ($found); $pth left as it was" >&2; exit 1 ;;
esac
tmp="$(mktemp "$site/.eikon.pth.XXXXXX")"
cp "$scratch/eikon.pth" "$tmp"
chmod 0644 "$tmp"
mv -f "$tmp" "$pth"
if [ "$system" = 1 ]; then
  found="$(cd / && env -u PYTHONPATH "$py" -c 'import eikon; print(eikon.__file__)')" || {
    echo "eikon: error: wrote $pth, but /usr/bin/python3 still cannot import eikon" >&2
    exit 1
  }
else
  found="$(import_via "$site")" || { echo "eikon: error: wrote $pth, but the import through it fails" >&2; exit 1; }
fi
case "$found" in
  "$moddir"/*) ;;
  *) echo "eikon: error: wrote $pth, but /usr/bin/python3 imports another eikon: $found" >&2; exit 1 ;;
esac
echo "eikon: python module registered: $pth -> $moddir (import eikon finds $found)"
