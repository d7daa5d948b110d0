#!/bin/sh
# report20's run of the benchmark set (tools/benchmark_scenes.py: the nine scenes and the three
# real-asset scenes) against Cycles 3.4 (host), 4.3 (trixie) and 5.2 (sid), main 5a37b40's library
# and add-on (build/portable/libdwivedi.so.1 and the packages of tools/package_addon.py, built by
# `cmake --build build --target dwivedi_bake_addon`), 64 x 64, --quick, one timing round; from the
# report20 worktree, as root (the chroots). The six reports ran at the same time from 12:49:30 UTC,
# niced (nice -n 19), beside six other helpers' builds and tests (load.log: the load average once
# a minute; times.log: each report's start and end with the load).
LIB=$PWD/build/portable/libdwivedi.so.1
D=docs/benchmark/versions64c
NINE=torus,head_back,head_point,sheet,box_side,marble,disc_back,bowl,cylinder_front
ASSETS=head_asset,candle,leaf_textured
(while true; do echo "$(date -u +%H:%M) $(cut -d' ' -f1-3 /proc/loadavg)" >> $D/load.log; sleep 60; done) &
LOGGER=$!
report() {  # $1: the folder under $D, $2: the Blender (host, trixie, sid), $3: the scenes
  echo "start $1 $(date -u +%H:%M:%S) load $(cut -d' ' -f1-3 /proc/loadavg)" >> $D/times.log
  DWIVEDI_LIBRARY=$LIB nice -n 19 /usr/bin/python3 tools/cycles_report.py --out $D/$1 \
      --sections cycles --cycles-scenes $3 --cycles-blenders $2 --quick --size 64 --repeats 1 --library $LIB
  echo "end $1 rc $? $(date -u +%H:%M:%S) load $(cut -d' ' -f1-3 /proc/loadavg)" >> $D/times.log
}
REPORTS=
for where in host trixie sid; do
  report $where $where $NINE &
  REPORTS="$REPORTS $!"
  report ${where}_assets $where $ASSETS &
  REPORTS="$REPORTS $!"
done
wait $REPORTS
kill $LOGGER
# The tables of docs/speed.md (this run against versions64b's) into summary.md:
python3 $D/summary.py > $D/summary.md
