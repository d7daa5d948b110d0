#!/usr/bin/env bash
# valgrind memcheck of the C tests and of `dwivedi estimate` on every shape and technique, from an
# existing build (default build/, as scripts/test.sh makes it). Fails on any memcheck error or
# definitely lost block, and helgrind (data races) on the thread-safety test. Usage: scripts/test-valgrind.sh [build-dir]
#
# Left out, with the reason: the statistical walk tests (tests/unit/test_walk_{agreement,halfspace,
# slab,energy,channels,bookkeeping}.c, tests/internal/test_walk_planted.c) and the Dwivedi sampling
# histograms (test_sampling_dwivedi.c) run 10^5 to 10^7 walks or samples: hours under valgrind.
# The same code paths run here through `dwivedi estimate` with few walks, and those tests run
# whole under ASan + UBSan (scripts/test-sanitizers.sh). Any new C test is included by default.
#
# Only memcheck's verdict counts here (exit status 99): whether a test passes is the normal
# suite's business, and one cannot pass under valgrind: test_v0 checks long double sums to 1e-17,
# and valgrind computes x87 long double in 64 bits.
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
command -v valgrind >/dev/null || { echo "test-valgrind: valgrind not found (apt-get install valgrind)" >&2; exit 2; }
skip='^(unit_test_walk_(agreement|halfspace|slab|energy|channels|bookkeeping)|internal_test_walk_planted|unit_test_sampling_dwivedi)$'
memcheck=(valgrind -q --tool=memcheck --error-exitcode=99 --leak-check=full --errors-for-leak-kinds=definite
          --show-leak-kinds=definite --track-origins=yes)
log=$(mktemp -d /tmp/dwivedi-valgrind.XXXXXX)
trap 'rm -rf "$log"' EXIT
failed=0 ran=0

run() { # name command...
  local name=$1; shift
  local start=$SECONDS rc=0
  "${memcheck[@]}" "$@" >"$log/$name.out" 2>"$log/$name.err" || rc=$?
  ran=$((ran + 1))
  if [ "$rc" -eq 99 ]; then
    failed=$((failed + 1))
    echo "FAIL  $name: memcheck errors ($((SECONDS - start)) s)"
    cat "$log/$name.err"
  elif [ "$rc" -ne 0 ]; then
    echo "ok    $name: memcheck clean; the program itself exited $rc under valgrind ($((SECONDS - start)) s)"
  else
    echo "ok    $name ($((SECONDS - start)) s)"
  fi
}

for exe in "$build"/tests/unit_test_* "$build"/tests/internal_test_*; do
  [ -x "$exe" ] || continue
  name=$(basename "$exe")
  if [[ $name =~ $skip ]]; then echo "skip  $name (statistical: see the top of this script)"; continue; fi
  run "$name" "$exe"
done

# The fuzz corpora and regressions, replayed (tests/fuzz/replay.c).
for exe in "$build"/tests/replay_*; do
  [ -x "$exe" ] || continue
  name=${exe##*/replay_}
  inputs=()
  for dir in tests/fuzz/corpus/"$name" tests/fuzz/regressions/"$name"; do [ -d "$dir" ] && inputs+=("$dir"); done
  [ ${#inputs[@]} -gt 0 ] && run "replay_$name" "$exe" "${inputs[@]}"
done

# Data races: helgrind on the thread-safety test (concurrent kernels, estimates, handles).
if [ -x "$build/tests/unit_test_thread_safety" ]; then
  memcheck_saved=("${memcheck[@]}")
  memcheck=(valgrind -q --tool=helgrind --error-exitcode=99)
  run "helgrind-unit_test_thread_safety" "$build/tests/unit_test_thread_safety"
  memcheck=("${memcheck_saved[@]}")
fi

cli="$build/dwivedi"
for technique in auto classical poe closest incident backward cycles; do
  run "estimate-halfspace-$technique" "$cli" estimate --scene halfspace --albedo 0.9 --technique "$technique" --walks 3000 --threads 2
  run "estimate-slab-$technique" "$cli" estimate --scene slab --thickness 2 --albedo 0.8,0.95,0.99 --light both \
    --incidence diffuse --technique "$technique" --walks 1500 --threads 2 --max-events 50
  run "estimate-sphere-$technique" "$cli" estimate --scene sphere --radius 1.5 --albedo 0.99 --anisotropy 0.3 \
    --light back --technique "$technique" --walks 1500 --threads 2
done
echo "valgrind memcheck: $ran runs, $failed with errors"
[ "$failed" -eq 0 ]
