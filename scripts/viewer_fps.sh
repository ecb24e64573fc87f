#!/usr/bin/env bash
# Frames/s of `eikon view` (docs/performance.md "Viewer"): opens the viewer on SCENE at W×H in a
# virtual X server (Xvfb, on a display it picks itself), drags across the window in STEPS small
# moves 0.25 s apart (each restarts the view with a coarse frame), lets the last view refine to
# --spp SPP and prints the viewer's summary line: the coarse frames' median time and frames/s,
# and the time from the last change to full quality (eikon render's default: 1 sample) and to SPP
# samples.
#
#   scripts/viewer_fps.sh build/apps/eikon scenes/glass_sphere.json [W H STEPS SPP]
set -euo pipefail
EIKON=${1:?usage: viewer_fps.sh EIKON SCENE [W H STEPS SPP]}
SCENE=${2:?usage: viewer_fps.sh EIKON SCENE [W H STEPS SPP]}
W=${3:-400} H=${4:-300} STEPS=${5:-20} SPP=${6:-4}
command -v Xvfb >/dev/null && command -v xdotool >/dev/null ||
  { echo "viewer_fps: needs Xvfb and xdotool (Debian xvfb, xdotool)" >&2; exit 1; }
tmp=$(mktemp -d)
Xvfb -displayfd 3 -screen 0 $((W + 64))x$((H + 64))x24 -nolisten tcp 3>"$tmp/display" 2>/dev/null &
xvfb=$!
trap 'kill $xvfb 2>/dev/null; wait $xvfb 2>/dev/null; rm -rf "$tmp"' EXIT
for _ in $(seq 100); do [ -s "$tmp/display" ] && break; sleep 0.1; done
export DISPLAY=:$(head -1 "$tmp/display")
"$EIKON" view "$SCENE" --width "$W" --height "$H" --spp "$SPP" >"$tmp/out" 2>"$tmp/err" &
viewer=$!
wid=$(timeout 300 xdotool search --sync --onlyvisible --name 'eikon view' | head -1)
# Wait for the first frame (the title then shows frames/s), then drag.
for _ in $(seq 600); do xdotool getwindowname "$wid" | grep -q 'frames/s' && break; sleep 0.5; done
x=$((W / 4)) y=$((H / 2))
xdotool mousemove --window "$wid" $x $y mousedown 1
for i in $(seq "$STEPS"); do
  xdotool mousemove --window "$wid" $((x + i * W / (2 * STEPS))) $y
  sleep 0.25
done
xdotool mouseup 1
sleep 1  # the last move's coarse frame, then the refinement: quit once it is done (or 300 s)
for _ in $(seq 1200); do xdotool getwindowname "$wid" | grep -q " | refined" && break; sleep 0.25; done
xdotool windowfocus "$wid" key q
wait $viewer
cat "$tmp/out"
grep -v '^$' "$tmp/err" >&2 || true
