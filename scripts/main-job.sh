#!/usr/bin/env bash
# The main job on its default settings: set up, build, then the diffusion-length report
# (bench of the four v0 methods against the mpmath table, plots and table into out/report/).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
build/dwivedi bench v0
/usr/bin/python3 tools/v0_report.py --cli build/dwivedi --out out/report
echo "main job: report written to out/report/"
