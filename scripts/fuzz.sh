#!/usr/bin/env bash
# Fuzz eikon's readers with libFuzzer (not run by CI; docs/testing.md).
#   scripts/fuzz.sh [SECONDS_PER_HARNESS] [HARNESS...]
# Configures build-fuzz (clang, EIKON_BUILD_FUZZERS=ON: every eikon library built with
# -fsanitize=address,undefined and fuzzer coverage), builds the harnesses fuzz/*.cpp (or those
# named: scene_json gemcad_asc fit_csv fit_yaml mesh_obj mesh_ply mesh_stl exr_latlong light_cache
# volume_cache spirv_cache pipeline_cache) and runs each for SECONDS_PER_HARNESS (default 600) on a copy of its seeds
# (fuzz/corpus/NAME, copied to build-fuzz/corpus/NAME, which keeps what the fuzzer adds). A
# finding (crash, sanitizer report, timeout of a single input, out-of-memory) is written to
# build-fuzz/findings/NAME/; the run goes on past findings (-fork), and prints one line per
# harness: executions, corpus size, new findings. Exits 1 if any harness found anything.
# Reproduce a finding: build-fuzz/fuzz/fuzz_NAME build-fuzz/findings/NAME/crash-...
# Needs clang with libFuzzer: installed with apt when missing (as root), else the command is shown.
# Environment: EIKON_FUZZ_BUILD_DIR (default build-fuzz), EIKON_FUZZ_JOBS (parallel compile jobs,
# default nproc), EIKON_FUZZ_RSS_MB (memory cap of one input, default 2048).
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-600}"
[ $# -gt 0 ] && shift
case "$seconds" in ''|*[!0-9]*) echo "eikon: error: SECONDS_PER_HARNESS must be a whole number, got '$seconds'" >&2; exit 2 ;; esac
build="${EIKON_FUZZ_BUILD_DIR:-build-fuzz}"
jobs="${EIKON_FUZZ_JOBS:-$(nproc)}"
rss="${EIKON_FUZZ_RSS_MB:-2048}"

# clang with libFuzzer: a program that links -fsanitize=fuzzer.
have_libfuzzer() {
  command -v clang++ >/dev/null 2>&1 || return 1
  local dir; dir="$(mktemp -d)"
  printf '%s\n' '#include <cstdint>' '#include <cstddef>' \
    'extern "C" int LLVMFuzzerTestOneInput(const uint8_t*, size_t) { return 0; }' >"$dir/t.cpp"
  clang++ -fsanitize=fuzzer,address "$dir/t.cpp" -o "$dir/t" >/dev/null 2>&1
  local rc=$?
  rm -rf "$dir"
  return $rc
}
if ! have_libfuzzer; then
  if [ "$(id -u)" -eq 0 ]; then
    echo "eikon: clang with libFuzzer not found: installing the Debian package clang with apt (as root)"
    DEBIAN_FRONTEND=noninteractive apt-get update -qq
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends clang >/dev/null
    have_libfuzzer || { echo "eikon: error: clang installed, but it cannot link -fsanitize=fuzzer" >&2; exit 1; }
  else
    echo "eikon: error: clang with libFuzzer not found; install it as root: apt-get install clang" >&2
    exit 1
  fi
fi

all=()
for f in fuzz/*.cpp; do all+=("$(basename "$f" .cpp)"); done
harnesses=("$@")
[ ${#harnesses[@]} -gt 0 ] || harnesses=("${all[@]}")
for h in "${harnesses[@]}"; do
  [ -f "fuzz/$h.cpp" ] || { echo "eikon: error: no harness '$h' (fuzz/$h.cpp); there are: ${all[*]}" >&2; exit 2; }
done

launcher=()
if command -v ccache >/dev/null 2>&1; then launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache); fi
CC=clang CXX=clang++ cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo "${launcher[@]}" \
  -DEIKON_BUILD_FUZZERS=ON -DEIKON_BUILD_TESTS=OFF -DEIKON_BUILD_BENCHMARKS=OFF \
  -DEIKON_BUILD_PYTHON=OFF >/dev/null
targets=()
for h in "${harnesses[@]}"; do targets+=("fuzz_$h"); done
cmake --build "$build" -j"$jobs" --target "${targets[@]}"

found_any=0
for h in "${harnesses[@]}"; do
  corpus="$build/corpus/$h" findings="$build/findings/$h" log="$build/logs/$h.log"
  mkdir -p "$corpus" "$findings" "$(dirname "$log")"
  [ -d "fuzz/corpus/$h" ] && cp -n fuzz/corpus/"$h"/* "$corpus"/ 2>/dev/null || true
  before="$(find "$findings" -type f | wc -l)"
  # -fork=1: a finding is saved and the run goes on in a fresh process; -ignore_*: every kind of
  # finding counts. Inputs up to 64 KiB; one input may run 10 s and use $rss MB.
  set +e
  "$build/fuzz/fuzz_$h" "$corpus" -fork=1 -ignore_crashes=1 -ignore_timeouts=1 -ignore_ooms=1 \
    -max_total_time="$seconds" -max_len=65536 -timeout=10 -rss_limit_mb="$rss" \
    -artifact_prefix="$findings/" -print_final_stats=1 >"$log" 2>&1
  set -e
  after="$(find "$findings" -type f | wc -l)"
  # -fork prints progress lines "#N: cov: ..." with the running count of executions: the last.
  execs="$(grep -o '^#[0-9]*' "$log" | tail -1 | tr -d '#' || true)"
  new=$((after - before))
  [ "$new" -eq 0 ] || found_any=1
  printf 'eikon: fuzz %-15s %4d s  %10s execs  corpus %5d  new findings %d%s\n' "$h" "$seconds" \
    "${execs:-?}" "$(find "$corpus" -type f | wc -l)" "$new" \
    "$([ "$new" -eq 0 ] || echo " (in $findings; log $log)")"
done
exit "$found_any"
