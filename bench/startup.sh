#!/usr/bin/env bash
# Time to the first dispatch of a repeated small render (the aim: a repeated render of a 64x48
# image starts its first dispatch within 0.5 s of the process start; docs/performance.md
# "Start-up"). For each scene, runs
#   eikon render SCENE --width 64 --height 48 --spp 1 -q --timings -o TMP/out.exr
# once to warm the caches (light cache, pipeline cache, Mesa's shader cache), then --reps times,
# and prints per scene the median over the repeats of each --timings stage (seconds since the
# process started; "first dispatch" is the criterion) and of the process CPU time (user + sys,
# which load on a shared machine inflates less than wall time).
#
#   bench/startup.sh [--eikon PATH] [--reps N] [SCENE.json ...]
#
# Default scenes: glass_sphere, diamond_brilliant, calcite_rhomb. The caches are the user's own
# ($EIKON_CACHE_DIR or ~/.cache/eikon, and Mesa's), as for any repeated run.
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
eikon="$here/build/apps/eikon"
reps=3
scenes=()
while [[ $# -gt 0 ]]; do
  case "$1" in
    --eikon) eikon="${2:?--eikon needs a path}"; shift 2 ;;
    --reps) reps="${2:?--reps needs a number}"; shift 2 ;;
    -h|--help) sed -n '2,14p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'; exit 0 ;;
    -*) echo "startup.sh: error: unknown option '$1'" >&2; exit 2 ;;
    *) scenes+=("$1"); shift ;;
  esac
done
if ! [[ "$reps" =~ ^[1-9][0-9]?$ ]]; then
  echo "startup.sh: error: --reps must be in [1, 99], got '$reps'" >&2
  exit 2
fi
[[ -x "$eikon" ]] || { echo "startup.sh: error: --eikon: not an executable file, got '$eikon'" >&2; exit 2; }
[[ ${#scenes[@]} -gt 0 ]] || scenes=("$here/scenes/glass_sphere.json" "$here/scenes/diamond_brilliant.json" "$here/scenes/calcite_rhomb.json")

tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
run() {  # run SCENE LOG: one render, its --timings lines and "cpu T" in LOG
  if ! /usr/bin/time -f 'cpu %U %S' -o "$tmp/time" "$eikon" render "$1" --width 64 --height 48 --spp 1 -q \
       --timings -o "$tmp/out.exr" >/dev/null 2>"$2"; then
    echo "startup.sh: error: eikon render $1 failed:" >&2; cat "$2" >&2; exit 1
  fi
  awk '{printf "eikon: timing: %.3f s  +0 s  process cpu (user+sys)\n", $2 + $3}' "$tmp/time" >>"$2"
}
for scene in "${scenes[@]}"; do
  [[ -f "$scene" ]] || { echo "startup.sh: error: no such scene file, got '$scene'" >&2; exit 2; }
done
echo "eikon: $("$eikon" --version 2>/dev/null | head -1 || true)  load: $(cut -d' ' -f1-3 /proc/loadavg)"
for scene in "${scenes[@]}"; do
  run "$scene" "$tmp/warm.log"
  for ((i = 0; i < reps; ++i)); do run "$scene" "$tmp/run$i.log"; done
  echo "$(basename "$scene") (64x48, median of $reps repeated runs, seconds since process start):"
  cat "$tmp"/run*.log | awk -v n="$reps" '
    /^eikon: timing:/ {
      stage = $0; sub(/^eikon: timing: +[0-9.]+ s +\+[0-9.]+ s +/, "", stage)
      if (!(stage in count)) order[++k] = stage
      v[stage, ++count[stage]] = $3
    }
    END {
      for (j = 1; j <= k; ++j) {
        s = order[j]; m = count[s]
        for (a = 1; a <= m; ++a) x[a] = v[s, a]
        for (a = 1; a <= m; ++a) for (b = a + 1; b <= m; ++b) if (x[b] < x[a]) { t = x[a]; x[a] = x[b]; x[b] = t }
        med = (m % 2) ? x[(m + 1) / 2] : (x[m / 2] + x[m / 2 + 1]) / 2
        printf "  %-26s %8.3f s%s\n", s, med, (s == "first dispatch" ? "   <- goal 0.5 s" : "")
      }
    }'
  rm -f "$tmp"/run*.log
done
