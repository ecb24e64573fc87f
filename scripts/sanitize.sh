#!/usr/bin/env bash
# Build the whole suite with AddressSanitizer and UndefinedBehaviorSanitizer and run it (not run by
# CI; docs/testing.md).
#   scripts/sanitize.sh [CTEST_ARGS...]        e.g. scripts/sanitize.sh -R 'Cli\.|AtomicWrite'
# Configures build-asan (RelWithDebInfo, -fsanitize=address,undefined -fno-omit-frame-pointer,
# the system's C++ compiler), builds everything and runs ctest there in two passes, then prints
# the counts of both:
#   1. every test but the Python module's, with leak detection on: any ASan, UBSan or LSan report
#      fails its test (UBSAN_OPTIONS=halt_on_error=1);
#   2. the Python module's tests (python.*): /usr/bin/python3 is not instrumented, so the ASan
#      runtime is preloaded (LD_PRELOAD; it must be the first library loaded) for ctest and the
#      interpreters it starts, and leak detection is off there (the interpreter keeps its objects
#      at exit by design, which LSan would report as leaks of the test).
# Leaks inside the Vulkan loader, Mesa's lavapipe and the validation layers are not eikon's: they
# are suppressed by scripts/lsan_suppressions.txt. Tests that need an address-space limit
# (RLIMIT_AS) skip themselves under ASan (tests/sanitizers.h). Exits 1 if any test failed.
# Environment: EIKON_ASAN_BUILD_DIR (default build-asan), EIKON_ASAN_JOBS (default nproc).
set -euo pipefail
cd "$(dirname "$0")/.."
root="$(pwd)"
build="${EIKON_ASAN_BUILD_DIR:-build-asan}"
jobs="${EIKON_ASAN_JOBS:-$(nproc)}"
sanitize="-fsanitize=address,undefined -fno-omit-frame-pointer"
launcher=()
if command -v ccache >/dev/null 2>&1; then launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache); fi
cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo "${launcher[@]}" \
  -DCMAKE_CXX_FLAGS="$sanitize" -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" \
  -DCMAKE_SHARED_LINKER_FLAGS="-fsanitize=address,undefined" \
  -DCMAKE_MODULE_LINKER_FLAGS="-fsanitize=address,undefined" >/dev/null
cmake --build "$build" -j"$jobs"

export EIKON_VALIDATION=1
export UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1
export LSAN_OPTIONS="suppressions=$root/scripts/lsan_suppressions.txt:print_suppressions=0"
asan_common=abort_on_error=0:strict_string_checks=1:check_initialization_order=1:detect_stack_use_after_return=1
mkdir -p "$build/sanitize"
status=0
ASAN_OPTIONS="detect_leaks=1:$asan_common" \
  ctest --test-dir "$build" -E '^python\.' -j"$jobs" --output-on-failure "$@" \
  | tee "$build/sanitize/ctest.log" || status=1

# The runtime the build linked: the compiler's libasan.
cxx="$(sed -n 's/^CMAKE_CXX_COMPILER:[A-Z]*=//p' "$build/CMakeCache.txt")"
libasan="$("$cxx" -print-file-name=libasan.so)"
python_ran=0
if [ -f "$libasan" ] && ctest --test-dir "$build" -N -R '^python\.' | grep -q 'Total Tests: [1-9]'; then
  python_ran=1
  LD_PRELOAD="$libasan" ASAN_OPTIONS="detect_leaks=0:$asan_common" \
    ctest --test-dir "$build" -R '^python\.' -j"$jobs" --output-on-failure "$@" \
    | tee "$build/sanitize/ctest-python.log" || status=1
elif [ ! -f "$libasan" ]; then
  echo "eikon: sanitize: no libasan.so for $cxx: the Python module's tests are left out" >&2
fi

# "N% tests passed, F tests failed out of T" of each pass, summed.
summary() { grep -Eo '[0-9]+ tests failed out of [0-9]+' "$1" | tail -1; }
failed=0 total=0
for log in "$build/sanitize/ctest.log" $([ "$python_ran" = 1 ] && echo "$build/sanitize/ctest-python.log"); do
  read -r f _ _ _ _ t <<<"$(summary "$log" || echo "0 tests failed out of 0")"
  failed=$((failed + f)) total=$((total + t))
done
skipped="$(cat "$build"/sanitize/ctest*.log | grep -c '\*\*\*Skipped\|Not Run' || true)"
echo "eikon: sanitize: $((total - failed)) passed, $failed failed, of $total tests" \
  "($skipped skipped or not run; logs in $build/sanitize/)"
[ "$failed" -eq 0 ] || status=1
exit "$status"
