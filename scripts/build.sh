#!/usr/bin/env bash
# Configure and build eikon (Release) into ${EIKON_BUILD_DIR:-build}, then register its Python
# module with Debian's python3 (scripts/install_python.sh: one eikon.pth file; see there).
# Uses ccache when it is installed (optional: a rebuild of an unchanged tree then takes seconds).
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR="${EIKON_BUILD_DIR:-build}"
launcher=()
if command -v ccache >/dev/null 2>&1; then launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache); fi
cmake -S . -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE=Release "${launcher[@]}" >/dev/null
cmake --build "$BUILD_DIR" -j"$(nproc)"
# Not fatal here (a non-root build still builds; `import eikon` then needs PYTHONPATH or
# sys.path.insert, docs/notebooks.md).
./scripts/install_python.sh "$BUILD_DIR" || echo "eikon: warning: Python module not registered (above); the build is done"
# The python3 on PATH, when it is another interpreter (pyenv, conda): registered too where its ABI
# is the module's, else a note naming /usr/bin/python3 (scripts/register_path_python.sh).
./scripts/register_path_python.sh "$BUILD_DIR" || true
