#!/usr/bin/env bash
# Writes tests/abi/libdwivedi.so.1.abi, the ABI of a release, with abidw (Debian abigail-tools).
# Usage: tests/abi/make_baseline.sh [commit]   (default: main, the last release)
# The baseline is the release's own library, built with debug information (RelWithDebInfo) so that
# abidw sees the public types' layouts; --headers-dir keeps only the types of capi/, and
# --short-locs/--no-corpus-path/--no-comp-dir-path keep the file free of this machine's paths.
# Run it only when a release is cut: the check compares every build against the last release.
set -euo pipefail
cd "$(dirname "$0")/../.."
commit=${1:-main}
scratch=$(mktemp -d /tmp/dwivedi-abi-base.XXXXXX)
trap 'git worktree remove --force "$scratch/src" 2>/dev/null || true; rm -rf "$scratch"' EXIT
git worktree add --detach "$scratch/src" "$commit" >/dev/null
cmake -S "$scratch/src" -B "$scratch/build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DDWV_BUILD_TESTS=OFF >/dev/null
cmake --build "$scratch/build" --target dwivedi -j "$(nproc)" >/dev/null
library=$(readlink -f "$scratch/build/libdwivedi.so.1")
abidw --headers-dir "$scratch/src/capi" --drop-private-types --no-corpus-path --no-comp-dir-path --short-locs \
  "$library" --out-file tests/abi/libdwivedi.so.1.abi
echo "wrote tests/abi/libdwivedi.so.1.abi from $(git rev-parse --short "$commit") ($(basename "$library"))"
