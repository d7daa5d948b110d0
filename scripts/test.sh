#!/usr/bin/env bash
# Sets up, builds with warnings as errors, and runs every test with ctest. With DWV_TEST_FULL=1 it
# then also runs valgrind memcheck of the C tests, the whole suite again under ASan + UBSan
# (build-asan/), and every fuzz target (build-fuzz/, DWV_FUZZ_SECONDS each, default 60). CI runs
# the first part only until the full run has been checked against the baker (see the README).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh -DDWV_WARNINGS_AS_ERRORS=ON
ctest --test-dir build --output-on-failure -j "$(nproc)"
if [ "${DWV_TEST_FULL:-0}" != 1 ]; then exit 0; fi
scripts/test-valgrind.sh build
scripts/test-sanitizers.sh
scripts/fuzz.sh "${DWV_FUZZ_SECONDS:-60}"
