#!/usr/bin/env bash
# Builds the libFuzzer targets (tests/fuzz/fuzz_*.c, clang + ASan + UBSan) into build-fuzz/ and
# runs each for SECONDS seconds (default 60) on a copy of its committed corpus.
# Usage: scripts/fuzz.sh [SECONDS] [TARGET...]      (targets by name: capi, scene_json...)
# A crash stops the run and leaves the input in build-fuzz/crashes/<name>/: add it to
# tests/fuzz/regressions/<name>/ (the replay tests run it in every build), then fix the bug.
# New coverage found stays in build-fuzz/corpus/<name>/; to grow the committed corpus, merge it:
#   build-fuzz/tests/fuzz/fuzz_<name> -merge=1 -use_counters=0 tests/fuzz/corpus/<name> build-fuzz/corpus/<name>
# (-use_counters=0 keeps one input per new edge, not per hit count: a small corpus)
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-60}
shift || true
build=${DWV_FUZZ_BUILD_DIR:-build-fuzz}
cc=${DWV_FUZZ_CC:-$(command -v clang-14 || command -v clang || true)}
[ -n "$cc" ] || { echo "fuzz: no clang (Debian: apt-get install clang-14 libclang-rt-14-dev)" >&2; exit 2; }
# the C++ part of the library (OpenColorIO) needs the matching clang++ for -fsanitize=fuzzer-no-link
cxx=${DWV_FUZZ_CXX:-$(command -v "${cc/clang/clang++}" || command -v clang++ || true)}
cmake -S . -B "$build" -DCMAKE_C_COMPILER="$cc" -DCMAKE_CXX_COMPILER="$cxx" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DDWV_BUILD_FUZZERS=ON \
  -DDWV_BUILD_TESTS=OFF -DDWV_WARNINGS_AS_ERRORS=ON >/dev/null
targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then
  for src in tests/fuzz/fuzz_*.c; do n=$(basename "$src" .c); targets+=("${n#fuzz_}"); done
fi
# Only the fuzz targets (static, with the library's objects): clang leaves the ASan runtime out of
# shared libraries, so the instrumented libdwivedi.so itself would not link with --no-undefined.
cmake --build "$build" -j "$(nproc)" --target "${targets[@]/#/fuzz_}"
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1}
status=0
for name in "${targets[@]}"; do
  exe="$build/tests/fuzz/fuzz_$name"
  [ -x "$exe" ] || { echo "fuzz: no target fuzz_$name" >&2; status=1; continue; }
  corpus="$build/corpus/$name"
  crashes="$build/crashes/$name"
  mkdir -p "$corpus" "$crashes"
  [ -d "tests/fuzz/corpus/$name" ] && cp -n tests/fuzz/corpus/"$name"/* "$corpus"/ 2>/dev/null || true
  echo "fuzz: $name for $seconds s"
  if ! "$exe" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -max_len=4096 -print_final_stats=1 \
      -artifact_prefix="$crashes/" "$corpus" 2>"$build/fuzz_$name.log"; then
    echo "fuzz: $name FOUND A CRASH (inputs in $crashes/):"
    grep -E "ERROR|SUMMARY|broken contract|runtime error" "$build/fuzz_$name.log" | head -20
    status=1
  else
    grep -E "stat::number_of_executed_units|stat::new_units_added|cov:" "$build/fuzz_$name.log" | tail -3
  fi
done
exit $status
