#!/usr/bin/env bash
# Configure and build eikon (Release) into ${EIKON_BUILD_DIR:-build}.
# Uses ccache when it is installed (it is optional: a rebuild of an unchanged tree is then seconds).
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD_DIR="${EIKON_BUILD_DIR:-build}"
launcher=()
if command -v ccache >/dev/null 2>&1; then launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache); fi
cmake -S . -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE=Release "${launcher[@]}" >/dev/null
cmake --build "$BUILD_DIR" -j"$(nproc)"
