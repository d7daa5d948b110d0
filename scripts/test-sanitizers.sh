#!/usr/bin/env bash
# Builds everything with AddressSanitizer + UndefinedBehaviorSanitizer into build-asan/ and runs
# the whole ctest suite there. Any report ends its process (-fno-sanitize-recover=all, ASan halts
# on the first error), so ctest sees it as a failed test.
# Usage: scripts/test-sanitizers.sh [extra cmake -D options...]
# Python tests and the installed-package test run processes that are not built with ASan (Python
# dlopens the library; the consumer test's compilers): tests/CMakeLists.txt LD_PRELOADs libasan
# there and turns off leak detection in those processes only (the interpreter's own memory is
# not ours to free); every C test runs with leak detection on.
set -euo pipefail
cd "$(dirname "$0")/.."
build=${DWV_ASAN_BUILD_DIR:-build-asan}
cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Release -DDWV_SANITIZE=ON -DDWV_WARNINGS_AS_ERRORS=ON "$@"
cmake --build "$build" -j "$(nproc)"
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:strict_string_checks=1:detect_stack_use_after_return=1:check_initialization_order=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1}
# tools/walk_report.py's test (tests/python/test_walk_report.py) starts hundreds of `dwivedi`
# processes, each paying ASan's start-up, within its own 300 s limit: run beside the rest on a
# loaded machine it ran out (a timeout, not a finding), so it runs after them, alone.
ctest --test-dir "$build" --output-on-failure -j "$(nproc)" --timeout 600 -E 'test_walk_report$'
ctest --test-dir "$build" --output-on-failure --timeout 600 -R 'test_walk_report$'
