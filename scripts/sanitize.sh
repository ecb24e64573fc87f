#!/usr/bin/env bash
# Build the whole suite with AddressSanitizer and UndefinedBehaviorSanitizer and run it (not run by
# CI; docs/testing.md).
#   scripts/sanitize.sh [CTEST_ARGS...]        e.g. scripts/sanitize.sh -R 'Cli\.|AtomicWrite'
# Configures build-asan (RelWithDebInfo, -fsanitize=address,undefined -fno-omit-frame-pointer,
# the system's C++ compiler), builds everything and runs ctest there in two passes, then prints
# the counts of each (run, passed, failed, skipped). CTEST_ARGS (-R, -E, -j, ...) go to both
# passes; the passes are told apart by the label "python", so do not give -L or -LE.
#   1. every test but the Python module's, with leak detection on: any ASan, UBSan or LSan report
#      fails its test (UBSAN_OPTIONS=halt_on_error=1);
#   2. the Python module's tests (label python): /usr/bin/python3 is not instrumented, so the ASan
#      runtime is preloaded (LD_PRELOAD; it must be the first library loaded) for ctest and the
#      interpreters it starts, and leak detection is off there (the interpreter keeps its objects
#      at exit by design, which LSan would report as leaks of the test).
# Leaks inside the Vulkan loader, Mesa's lavapipe and the validation layers are not eikon's: they
# are suppressed by scripts/lsan_suppressions.txt; the programs are linked to lavapipe so that it
# stays loaded until LeakSanitizer looks (below). Tests that need an address-space limit
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
# Mesa's lavapipe keeps one block (128 bytes, allocated under pthread_once) to its end, but the
# Vulkan loader unloads the driver with its last instance, so LeakSanitizer, which looks at exit,
# reports the block from an unknown module that no suppression can name. This build's programs
# are therefore linked to the driver (a DT_NEEDED kept by --no-as-needed): loaded at start, it is
# never unloaded, and the block stays reachable from its globals (or is suppressed by name).
# Only this build does so; eikon's own programs leave the driver to the loader. Where lavapipe is
# not installed nothing is added.
keep_lavapipe=""
if [ "$("${CXX:-c++}" -print-file-name=libvulkan_lvp.so)" != libvulkan_lvp.so ]; then
  keep_lavapipe=" -Wl,--push-state,--no-as-needed,-l:libvulkan_lvp.so,--pop-state"
fi
cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo "${launcher[@]}" \
  -DCMAKE_CXX_FLAGS="$sanitize" \
  -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined$keep_lavapipe" \
  -DCMAKE_SHARED_LINKER_FLAGS="-fsanitize=address,undefined" \
  -DCMAKE_MODULE_LINKER_FLAGS="-fsanitize=address,undefined" >/dev/null
cmake --build "$build" -j"$jobs"

export EIKON_VALIDATION=1
export UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1
export LSAN_OPTIONS="suppressions=$root/scripts/lsan_suppressions.txt:print_suppressions=0"
asan_common=abort_on_error=0:strict_string_checks=1:check_initialization_order=1:detect_stack_use_after_return=1
mkdir -p "$build/sanitize"
rm -f "$build"/sanitize/ctest*.log

# The two passes are told apart by the label "python" (python/CMakeLists.txt), not by a -R or -E:
# ctest keeps only the last -R and the last -E it is given, so those stay the caller's.
status=0
selects() { ctest --test-dir "$build" -N "$@" | grep 'Total Tests: [1-9]' >/dev/null; }
cxx_ran=0
if selects "$@" -LE '^python$'; then
  cxx_ran=1
  ASAN_OPTIONS="detect_leaks=1:$asan_common" \
    ctest --test-dir "$build" -j"$jobs" --output-on-failure "$@" -LE '^python$' \
    | tee "$build/sanitize/ctest.log" || status=1
fi

# The runtime the build linked: the compiler's libasan, preloaded with the C++ runtime after it:
# ASan finds the functions it intercepts (__cxa_throw) in the libraries loaded at its start, and
# the interpreter does not link libstdc++, so without it the module's first C++ throw stops the
# process ("CHECK failed: ... real___cxa_throw").
cxx="$(sed -n 's/^CMAKE_CXX_COMPILER:[A-Z]*=//p' "$build/CMakeCache.txt")"
libasan="$("$cxx" -print-file-name=libasan.so)"
libstdcxx="$("$cxx" -print-file-name=libstdc++.so)"
python_ran=0
if selects "$@" -L '^python$' && [ -f "$libasan" ]; then
  python_ran=1
  LD_PRELOAD="$libasan $libstdcxx" ASAN_OPTIONS="detect_leaks=0:$asan_common" \
    ctest --test-dir "$build" -j"$jobs" --output-on-failure "$@" -L '^python$' \
    | tee "$build/sanitize/ctest-python.log" || status=1
elif selects "$@" -L '^python$'; then
  echo "eikon: sanitize: no libasan.so for $cxx: the Python module's tests are left out" >&2
  status=1
fi

# One line per pass: ctest's "F tests failed out of T" (a test that could not start, "***Not Run",
# is a failure) and its skipped tests (a GTEST_SKIP, "***Skipped", counted by its result line).
total_failed=0
report() {
  local log="$1" pass="$2" f t s
  if ! read -r f _ _ _ _ t < <(grep -Eo '[0-9]+ tests failed out of [0-9]+' "$log" | tail -1) ||
    [ -z "$t" ]; then
    echo "eikon: sanitize: $pass: ctest printed no counts (see $log)"
    total_failed=$((total_failed + 1))
    return
  fi
  s="$(grep -Ec 'Test +#[0-9]+: .*\*\*\*Skipped' "$log" || true)"
  echo "eikon: sanitize: $pass: $t run, $((t - f - s)) passed, $f failed, $s skipped"
  total_failed=$((total_failed + f))
}
[ "$cxx_ran" = 0 ] || report "$build/sanitize/ctest.log" "C++ and repository tests"
[ "$python_ran" = 0 ] || report "$build/sanitize/ctest-python.log" "Python module tests (python.*)"
[ "$cxx_ran$python_ran" != 00 ] || { echo "eikon: sanitize: no test selected" >&2; status=1; }
echo "eikon: sanitize: logs in $build/sanitize/"
[ "$total_failed" -eq 0 ] || status=1
exit "$status"
