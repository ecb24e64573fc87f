#!/usr/bin/env bash
# One command from a fresh Debian 12 clone to a picture: installs the packages eikon needs,
# builds it (Release, build/), and renders scenes/glass_sphere.json to out/glass_sphere.exr + .png.
set -euo pipefail
cd "$(dirname "$0")"
./scripts/install_deps.sh
./scripts/build.sh
mkdir -p out
./build/apps/eikon render scenes/glass_sphere.json -o out/glass_sphere.exr
