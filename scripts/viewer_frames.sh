#!/usr/bin/env bash
# The README's orbit strip (docs/images/viewer_orbit_K.png): `eikon view` on a scene in a virtual
# X server, one run per frame, each dragged K steps of (DX, DY) pixels from the start and refined
# to SPP samples, its screenshot kept. Needs Xvfb and xdotool.
#
#   scripts/viewer_frames.sh build/apps/eikon scenes/glass_sphere.json docs/images [W H SPP FRAMES DX DY]
set -euo pipefail
EIKON=${1:?usage: viewer_frames.sh EIKON SCENE OUTDIR [W H SPP FRAMES DX DY]}
SCENE=${2:?scene}
OUT=${3:?output folder}
W=${4:-400} H=${5:-300} SPP=${6:-4} FRAMES=${7:-4} DX=${8:-50} DY=${9:-16}
tmp=$(mktemp -d)
Xvfb -displayfd 3 -screen 0 $((W + 64))x$((H + 64))x24 -nolisten tcp 3>"$tmp/display" 2>/dev/null &
xvfb=$!
trap 'kill $xvfb 2>/dev/null; wait $xvfb 2>/dev/null; rm -rf "$tmp"' EXIT
for _ in $(seq 100); do [ -s "$tmp/display" ] && break; sleep 0.1; done
export DISPLAY=:$(head -1 "$tmp/display")
mkdir -p "$OUT"
for k in $(seq 0 $((FRAMES - 1))); do
  "$EIKON" view "$SCENE" --width "$W" --height "$H" --spp "$SPP" --exit-after-frames 1000 \
    --wait-for-input --screenshot "$OUT/viewer_orbit_$((k + 1)).png" >"$tmp/out" 2>&1 &
  viewer=$!
  x=$((W / 4)) y=$((H / 3))
  timeout 300 xdotool search --sync --onlyvisible --name 'eikon view' \
    mousemove --window %1 $x $y mousedown 1 \
    mousemove --window %1 $((x + k * DX)) $((y + k * DY)) mouseup 1 >/dev/null
  wait $viewer
  grep '"camera"' "$tmp/out"
done
