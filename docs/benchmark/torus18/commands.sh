#!/bin/sh
# torus18: the benchmark torus against Cycles 3.4 (host), 4.3 (trixie) and 5.2 (sid), before
# (--walk-event-cap 0: the add-on's default 10^6, as the bench18 run) and after (the report's
# default now, Cycles' 256), 32 x 32, --quick, one timing round, from the worktree at torus18's
# head, as root (the chroots), niced, beside other helpers' runs (load average 15-17): the times of
# the three reports are not comparable with each other, the converged means and variance ratios are.
LIB=$PWD/build/portable/libdwivedi.so.1
OUT=docs/benchmark/torus18
COMMON="--sections cycles --cycles-scenes torus --quick --size 32 --repeats 1 --library $LIB"
DWIVEDI_LIBRARY=$LIB nice /usr/bin/python3 tools/cycles_report.py --out $OUT/cap0_host $COMMON --cycles-blenders host --walk-event-cap 0
DWIVEDI_LIBRARY=$LIB nice /usr/bin/python3 tools/cycles_report.py --out $OUT/cap0_chroots $COMMON --cycles-blenders trixie,sid --walk-event-cap 0
DWIVEDI_LIBRARY=$LIB nice /usr/bin/python3 tools/cycles_report.py --out $OUT/cap256 $COMMON --cycles-blenders host,trixie,sid
