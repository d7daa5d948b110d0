#!/usr/bin/env bash
# The main job on its default settings: set up, build, then bake the built-in default scene (a thin
# back-lit leaf-like shell beside a thick front-lit wax-like shape) into out/default.exr (scene
# linear, with variance and sample counts), out/default.png (display image) and out/default.json.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
mkdir -p out
build/dwivedi bake --out out/default
echo "main job: wrote out/default.exr, out/default.png and out/default.json"
