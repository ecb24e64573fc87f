#!/usr/bin/env bash
# Runs every test on its own from a fresh clone: installs missing packages, builds, runs the
# GoogleTest suite through CTest (Vulkan validation layers on), then executes the notebooks.
set -euo pipefail
cd "$(dirname "$0")"
./scripts/install_deps.sh
./scripts/build.sh
export EIKON_VALIDATION=1
ctest --test-dir build --output-on-failure -j"$(nproc)"
if [ -x scripts/run_notebooks.sh ] && ls notebooks/*.ipynb >/dev/null 2>&1; then
  ./scripts/run_notebooks.sh build
fi
