#!/usr/bin/env bash
# The README's test command, and CI's (.ci/run). Sets up, builds with warnings as errors, then:
#   1. ctest: every test in build/ (the reduced stability report, stability.quick, among them);
#   2. the whole suite again under ASan + UBSan in build-asan/ (scripts/test-sanitizers.sh; the
#      Blender tests are not registered there: Blender is not built with ASan);
#   3. every libFuzzer target for DWV_FUZZ_SECONDS seconds each (default 60) on a copy of its
#      committed corpus, in build-fuzz/ (scripts/fuzz.sh);
#   4. with DWV_TEST_VALGRIND=1 only: valgrind memcheck of the C tests, the fuzz corpora and
#      `dwivedi estimate`, and helgrind on the thread-safety test (scripts/test-valgrind.sh). Not
#      by default: it alone took 13 of the 36.6 minutes the four parts took from a fresh clone on
#      the shared 2-core machine (docs/hardening.md), past CI's 30-minute budget.
# Every part runs even when an earlier one failed (CI then shows every finding at once); the exit
# status is non-zero if any failed. Each part's wall time and CPU time (user + system of its
# processes; on a shared machine the better measure of what it costs) are printed at the end.
#   DWV_TEST_QUICK=1     part 1 only, without the tests in other Blenders' chroots (ctest label
#                        "chroot": they need root and make two Debian chroots once)
#   DWV_TEST_VALGRIND=1  part 4 too
#   DWV_TEST_PORTABLE=0  skip the portable library (its static dependencies and its test)
#   DWV_TEST_PARTS       the parts by name, e.g. "ctest fuzz" (names: ctest asan fuzz valgrind)
set -uo pipefail
cd "$(dirname "$0")/.."

default_parts="ctest asan fuzz"
[ "${DWV_TEST_VALGRIND:-0}" = 1 ] && default_parts+=" valgrind"
parts=${DWV_TEST_PARTS:-$default_parts}
[ "${DWV_TEST_QUICK:-0}" = 1 ] && parts=ctest
failed=() timings=()

# cpu: CPU seconds (user + system) of this shell's finished children so far, into $CPU. `times`
# must run in this shell (not in a pipeline or $(...), whose subshell has no such children).
times_file=$(mktemp)
trap 'rm -f "$times_file"' EXIT
cpu() {
  times >"$times_file"
  CPU=$(tail -1 "$times_file" | awk '{ split($1, u, /[ms]/); split($2, s, /[ms]/); printf "%.0f", u[1] * 60 + u[2] + s[1] * 60 + s[2] }')
}

part() { # name command...
  local name=$1; shift
  [[ " $parts " == *" $name "* ]] || return 0
  echo "==== test.sh: $name: $*"
  local start=$SECONDS cpu0 verdict=ok
  cpu; cpu0=$CPU
  "$@" || { verdict=FAILED; failed+=("$name"); }
  cpu
  timings+=("$name: $((SECONDS - start)) s wall, $((CPU - cpu0)) s CPU, $verdict")
}

start=$SECONDS
# The portable library the Blender packages carry (issue 16): its static dependencies, built once
# into a cache outside the clone (scripts/build-portable-deps.sh; DWV_TEST_PORTABLE=0 skips it).
portable_args=()
if [ "${DWV_TEST_PORTABLE:-1}" = 1 ]; then
  if ! portable_prefix=$(scripts/build-portable-deps.sh | tail -n 1) || [ ! -f "$portable_prefix/.complete" ]; then
    echo "test.sh: scripts/build-portable-deps.sh failed" >&2; exit 1
  fi
  portable_args=(-DDWV_PORTABLE_DEPS="$portable_prefix")
  cpu
  timings+=("portable dependencies: $((SECONDS - start)) s wall, $CPU s CPU")
fi
setup_start=$SECONDS setup_cpu0=${CPU:-0}
if ! scripts/setup.sh -DDWV_WARNINGS_AS_ERRORS=ON "${portable_args[@]}"; then echo "test.sh: setup or build failed" >&2; exit 1; fi
cpu
timings+=("setup and build: $((SECONDS - setup_start)) s wall, $((CPU - setup_cpu0)) s CPU")
ctest_args=()
[ "${DWV_TEST_QUICK:-0}" = 1 ] && ctest_args=(-LE chroot)
part ctest ctest --test-dir build --output-on-failure -j "$(nproc)" "${ctest_args[@]}"
part asan scripts/test-sanitizers.sh
part fuzz scripts/fuzz.sh "${DWV_FUZZ_SECONDS:-60}"
part valgrind scripts/test-valgrind.sh build

cpu
echo "==== test.sh: time per part (total $((SECONDS - start)) s wall, $CPU s CPU)"
printf '  %s\n' "${timings[@]}"
if [ ${#failed[@]} -gt 0 ]; then
  echo "test.sh: FAILED: ${failed[*]}" >&2
  exit 1
fi
