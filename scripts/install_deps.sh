#!/usr/bin/env bash
# Install eikon's Debian 12 packages if any are missing (non-interactive; needs root or sudo).
# Used by setup.sh and test.sh; safe to run again (it does nothing when all are present).
set -euo pipefail
PKGS=(
  build-essential cmake pkg-config git
  libvulkan-dev mesa-vulkan-drivers vulkan-tools glslang-tools spirv-tools vulkan-validationlayers
  libglm-dev libceres-dev libopenexr-dev libpng-dev
  nlohmann-json3-dev libcli11-dev libyaml-cpp-dev
  googletest libgtest-dev libbenchmark-dev universal-ctags clang-format
  pybind11-dev python3-pybind11 python3-dev python3-numpy python3-scipy python3-matplotlib python3-tqdm
  python3-distributed python3-pandas
  jupyter-nbconvert python3-nbformat python3-ipykernel
  libglfw3-dev xvfb xdotool
  openimageio-tools
)
missing=()
for p in "${PKGS[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "eikon: all ${#PKGS[@]} Debian packages present"
  exit 0
fi
echo "eikon: installing ${#missing[@]} Debian packages: ${missing[*]}"
SUDO=""
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || { echo "eikon: error: need root or sudo to install: ${missing[*]}" >&2; exit 1; }
  SUDO="sudo"
fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
echo "eikon: packages installed"
