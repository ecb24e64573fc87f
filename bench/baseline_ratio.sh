#!/usr/bin/env bash
# Throughput of eikon's GPU march against a lean baseline, measured in one sitting
# (docs/performance.md "Figures"). Prints, from one run:
#   - steps/s of eikon's naive Euler march (smoothed interfaces, 1-voxel steps, no skipping, no
#     Fresnel: two trilinear field fetches per step) against the baseline's Euler march (also two
#     per step), glass_sphere at 800x600 from a 128³ volume;
#   - the default render (sharp interfaces) on the GPU against the CPU twin (view_bench);
#   - the whole process `eikon render scenes/glass_sphere.json` (start-up included) against the
#     baseline's whole process.
#
#   bench/baseline_ratio.sh [--baseline PATH] [--build DIR] [--reps N]
#
# The baseline is a development aid outside this repository: a minimal Vulkan compute program that
# marches the same problem (800x600 rays, a 128³ glass sphere volume read as storage images, 8
# imageLoads and a manual trilinear mix per sample, Euler steps of half a voxel) and prints a line
#   RESULT ...: median dispatch T ms (...); rays/s R; samples(steps)/s S; texture fetches/s F; ...
# Give its binary with --baseline or $EIKON_BASELINE; it is run as `BASELINE REPS out.exr` in a
# temporary directory. Without it the baseline rows are skipped (and said so). Timings on a shared
# machine vary by ±30%: compare the ratios, which are measured side by side.
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
baseline="${EIKON_BASELINE:-}"
build="$here/build"
reps=5
while [[ $# -gt 0 ]]; do
  case "$1" in
    --baseline) baseline="${2:?--baseline needs a path}"; shift 2 ;;
    --build) build="${2:?--build needs a directory}"; shift 2 ;;
    --reps) reps="${2:?--reps needs a number}"; shift 2 ;;
    -h|--help) sed -n '2,21p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "baseline_ratio.sh: error: unknown argument '$1'" >&2; exit 2 ;;
  esac
done
if ! [[ "$reps" =~ ^[1-9][0-9]?$ ]]; then
  echo "baseline_ratio.sh: error: --reps must be in [1, 99], got '$reps'" >&2
  exit 2
fi
if [[ -n "$baseline" && ! -x "$baseline" ]]; then
  echo "baseline_ratio.sh: error: --baseline: not an executable file, got '$baseline'" >&2
  exit 2
fi
eikon="$build/apps/eikon"
bench="$build/bench/view_bench"
for b in "$eikon" "$bench"; do
  if [[ ! -x "$b" ]]; then
    echo "baseline_ratio.sh: error: $b not built (cmake --build $build --target eikon view_bench)" >&2
    exit 2
  fi
done
scene="$here/scenes/glass_sphere.json"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT

now() { date +%s.%N; }
# Field $2 (awk column) of the view_bench row whose variant name starts with $1.
row() { awk -v n="$1" -v c="$2" 'index($0, n) == 1 { print $c }'; }
ratio() { awk -v a="$1" -v b="$2" 'BEGIN { if (b > 0) printf "%.3g", a / b; else print "-" }'; }

# 1. The baseline (whole process, and its own dispatch statistics).
base_steps="" base_rays="" base_whole=""
if [[ -n "$baseline" ]]; then
  t0=$(now)
  (cd "$work" && "$baseline" "$reps" out.exr) >"$work/baseline.txt" 2>&1 || {
    echo "baseline_ratio.sh: error: the baseline failed:" >&2
    tail -3 "$work/baseline.txt" >&2
    exit 1
  }
  base_whole=$(awk -v a="$t0" -v b="$(now)" 'BEGIN { printf "%.2f", b - a }')
  line=$(grep '^RESULT' "$work/baseline.txt" || true)
  base_rays=$(sed -n 's/.*rays\/s \([0-9.e+-]*\);.*/\1/p' <<<"$line")
  base_steps=$(sed -n 's/.*samples(steps)\/s \([0-9.e+-]*\);.*/\1/p' <<<"$line")
  if [[ -z "$base_steps" ]]; then
    echo "baseline_ratio.sh: error: no 'RESULT ... samples(steps)/s' line from the baseline" >&2
    exit 1
  fi
fi

# 2. eikon's naive Euler march (same fetches per step as the baseline) and the default render.
"$bench" "$scene" --march smoothed --only naive --no-cpu --no-accuracy --repeat 3 \
  >"$work/naive.txt" 2>&1
naive_steps=$(row "naive Euler" 10 <"$work/naive.txt")
naive_rays=$(row "naive Euler" 8 <"$work/naive.txt")
"$bench" "$scene" --only "(default)" --no-accuracy --repeat 3 >"$work/default.txt" 2>&1
gpu_s=$(row "RK4, 0.25 voxel, skip (default)" 6 <"$work/default.txt")
cpu_s=$(sed -n 's/^CPU reference.*: \([0-9.]*\) s,.*/\1/p' "$work/default.txt")

# 3. eikon's whole process at the scene's size, 1 sample per pixel, default settings otherwise.
t0=$(now)
"$eikon" render "$scene" -o "$work/eikon.exr" -q --spp 1 >"$work/render.txt" 2>&1
eikon_whole=$(awk -v a="$t0" -v b="$(now)" 'BEGIN { printf "%.2f", b - a }')

echo "glass_sphere, 800x600, 128³, $(sed -n 's/.*device \(.*\)$/\1/p' "$work/naive.txt" | head -1)"
printf '%-58s %12s %12s %8s\n' "measure" "eikon" "other" "ratio"
if [[ -n "$baseline" ]]; then
  printf '%-58s %12s %12s %8s\n' "Euler steps/s, 2 fetches/step (eikon naive / baseline)" \
    "$naive_steps" "$base_steps" "$(ratio "$naive_steps" "$base_steps")"
  printf '%-58s %12s %12s %8s\n' "rays/s of those marches (eikon naive / baseline)" \
    "$naive_rays" "$base_rays" "$(ratio "$naive_rays" "$base_rays")"
  printf '%-58s %12s %12s %8s\n' "whole process [s] (baseline / eikon render: >1 = faster)" \
    "$eikon_whole" "$base_whole" "$(ratio "$base_whole" "$eikon_whole")"
else
  echo "(baseline rows skipped: give the baseline binary with --baseline PATH or EIKON_BASELINE)"
  printf '%-58s %12s %12s %8s\n' "Euler steps/s, 2 fetches/step (eikon naive)" "$naive_steps" "-" "-"
  printf '%-58s %12s %12s %8s\n' "whole process [s] (eikon render)" "$eikon_whole" "-" "-"
fi
printf '%-58s %12s %12s %8s\n' "default render [s] (CPU twin / GPU: >1 = GPU faster)" \
  "$gpu_s" "$cpu_s" "$(ratio "$cpu_s" "$gpu_s")"
