#!/bin/sh
# bench18's run of the benchmark set (tools/benchmark_scenes.py: the nine scenes and the three
# real-asset scenes) against Cycles 3.4 (host), 4.3 (trixie) and 5.2 (sid), main 5a7e0b4's library
# and add-on (build/portable/libdwivedi.so.1 from tools/package_addon.py's build), 64 x 64, --quick,
# one timing round; from a copy of the source tree, as root (the chroots). The host's nine ran
# 05:57-06:23 UTC, the other five reports at the same time from 06:13-06:16 (the machine's load
# would not let them finish one after the other), niced, beside other helpers' chroot tests: load
# average 13-30 (load.log; times.log: each report's start and end).
LIB=$PWD/build/portable/libdwivedi.so.1
NINE=torus,head_back,head_point,sheet,box_side,marble,disc_back,bowl,cylinder_front
ASSETS=head_asset,candle,leaf_textured
for where in host trixie sid; do
  DWIVEDI_LIBRARY=$LIB nice /usr/bin/python3 tools/cycles_report.py --out docs/benchmark/versions64b/$where \
      --sections cycles --cycles-scenes $NINE --cycles-blenders $where --quick --size 64 --repeats 1 --library $LIB &
  DWIVEDI_LIBRARY=$LIB nice /usr/bin/python3 tools/cycles_report.py --out docs/benchmark/versions64b/${where}_assets \
      --sections cycles --cycles-scenes $ASSETS --cycles-blenders $where --quick --size 64 --repeats 1 --library $LIB &
done
wait
# The host's nine ran under a python3 without matplotlib (no plots): its plots and report.md again
# from its report.json with Debian's python3 (python3-matplotlib):
DWIVEDI_LIBRARY=$LIB /usr/bin/python3 docs/benchmark/versions64b/replot.py docs/benchmark/versions64b/host
# The table of docs/speed.md:
python3 docs/benchmark/versions64b/summary.py
