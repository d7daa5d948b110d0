#!/usr/bin/env bash
# Installs what dwivedi needs on Debian 12 (as root, or through sudo) and builds it into build/.
# Usage: scripts/setup.sh [extra cmake -D options...]
set -euo pipefail
cd "$(dirname "$0")/.."

packages=(build-essential cmake pkg-config binutils python3 python3-mpmath python3-numpy python3-matplotlib
          libopenexr-dev openexr libopencolorio-dev opencolorio-tools libpng-dev libcjson-dev libassimp-dev libembree-dev
          abigail-tools valgrind clang-14 libclang-rt-14-dev)
# Blender 3.4 for the add-on's headless tests (tests/blender, registered only where it is found).
packages+=(blender)
# The add-on's packages in Blender 4.3 and 5.2: clean Debian chroots (scripts/blender-chroots.sh);
# lld-14 links the aarch64 library the load checks are tested with (tests/blender/fixtures.py).
packages+=(mmdebstrap lld-14)
# MPI for `mpirun -n N dwivedi bake ... --mpi` and its tests (tests/mpi; the CLI only, docs/farm.md).
packages+=(libopenmpi-dev openmpi-bin)
# A split bake through a real single-node Slurm in tests/farm (issue 21; the test starts its own daemons).
packages+=(slurm-wlm munge)
# node runs the Flamenco job type's compiler in tests/farm/test_flamenco_job.py.
packages+=(nodejs)
# Blender's real UI for tests/blender/test_ui.py: an X server without a screen (xvfb-run needs xauth).
packages+=(xvfb xauth)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  if [ "$(id -u)" -eq 0 ]; then as_root=(); else as_root=(sudo); fi
  echo "setup: installing ${missing[*]}"
  "${as_root[@]}" env DEBIAN_FRONTEND=noninteractive apt-get update -q
  "${as_root[@]}" env DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends "${missing[@]}"
fi

# The Blender packages carry the self-contained library, made from static dependencies that
# scripts/build-portable-deps.sh builds once into a cache (scripts/test.sh runs it): use that cache
# when it is complete and no -DDWV_PORTABLE_DEPS was given.
portable=()
if [[ " $* " != *" -DDWV_PORTABLE_DEPS="* ]]; then
  prefix=$(scripts/build-portable-deps.sh --print-prefix)
  [ -f "$prefix/.complete" ] && portable=(-DDWV_PORTABLE_DEPS="$prefix")
fi
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release "${portable[@]}" "$@"
cmake --build build -j "$(nproc)"
