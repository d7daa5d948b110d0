#!/usr/bin/env bash
# Sets up, builds with warnings as errors, and runs every test with ctest; then (CI does all of it)
# valgrind memcheck of the C tests, the whole suite again under ASan + UBSan (build-asan/), and a
# run of every fuzz target (build-fuzz/, DWV_FUZZ_SECONDS each, default 60). DWV_TEST_QUICK=1 stops
# after the first ctest.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh -DDWV_WARNINGS_AS_ERRORS=ON
ctest --test-dir build --output-on-failure -j "$(nproc)"
if [ "${DWV_TEST_QUICK:-0}" = 1 ]; then exit 0; fi
scripts/test-valgrind.sh build
scripts/test-sanitizers.sh
scripts/fuzz.sh "${DWV_FUZZ_SECONDS:-60}"
