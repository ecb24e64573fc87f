#!/usr/bin/env bash
# Execute every notebook in notebooks/ headless, top to bottom, with Debian's Jupyter.
#   scripts/run_notebooks.sh BUILD_DIR [--figures]
# BUILD_DIR must hold the built module (BUILD_DIR/python/eikon*.so; target eikon_python).
# Outputs go to a temporary directory, never back into notebooks/ (they are committed without outputs).
# --figures also writes the notebooks' PNG figures to docs/figures/ (for the README).
# Exits non-zero if any notebook fails; prints "notebooks: P passed, F failed".
set -u
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${1:?usage: run_notebooks.sh BUILD_DIR [--figures]}"
build="$(cd "$build" && pwd)"
export EIKON_BUILD_DIR="$build" EIKON_SOURCE_DIR="$here" PYDEVD_DISABLE_FILE_VALIDATION=1
if [ "${2:-}" = "--figures" ]; then export EIKON_FIGURES_DIR="$here/docs/figures"; fi
py=/usr/bin/python3   # the Debian interpreter (numpy, matplotlib, nbconvert); not a pyenv shim
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT
pass=0; fail=0
for nb in "$here"/notebooks/*.ipynb; do
  name="$(basename "$nb")"
  start=$(date +%s)
  if "$py" -Xfrozen_modules=off -m nbconvert --to notebook --execute --ExecutePreprocessor.timeout=600 \
       --output-dir "$out" "$nb" >"$out/$name.log" 2>&1; then
    pass=$((pass + 1)); echo "PASS $name ($(( $(date +%s) - start )) s)"
  else
    fail=$((fail + 1)); echo "FAIL $name ($(( $(date +%s) - start )) s)"; tail -n 30 "$out/$name.log"
  fi
done
echo "notebooks: $pass passed, $fail failed"
[ "$fail" -eq 0 ]
