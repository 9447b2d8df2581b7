#!/bin/bash
# usage: outputs_unchanged.sh OUT EXAMPLES  (EXAMPLES: a `volerr examples --out` folder)
# the outputs of nine commands on the shipped examples, for a diff -r between two trees
set -u
V=${VOLERR:-$(dirname "$0")/../../../.venv/bin/volerr}; O=$1; E=$2; mkdir -p $O
$V map MB1 --errors $E/errors_MB1 --out $O/map.csv >/dev/null 2>&1; echo "map $?"
$V diagonals DMU50 --errors $E/dmu50/errors --json $O/diag.json >/dev/null 2>&1; echo "diag $?"
$V compensate DMU50 --errors $E/dmu50/errors $E/dmu50/hemisphere.nc --out $O/hemi.nc >/dev/null 2>&1; echo "comp $?"
$V iso230-2 $E/iso230_2_run_X.csv --json $O/iso.json --tolerance "A=20,E=15" >/dev/null 2>&1; echo "iso $?"
$V probe-cal $E/probe_sphere.csv --sphere-radius 25.006 --out $O/probe.csv --json $O/probe.json >/dev/null 2>&1; echo "probe $?"
$V calibrate DMU50 $E/sphere_example_DMU50.csv --json $O/cal.json --errors-out $O/calerr >/dev/null 2>&1; echo "cal $?"
$V calibrate MB1 $E/ballbar/ballbar_XY.csv $E/ballbar/ballbar_YZ.csv $E/ballbar/ballbar_ZX.csv --json $O/bb.json >/dev/null 2>&1; echo "bb $?"
$V iso10360 MB1 --errors $E/errors_MB1 --mpe "E0=2+L/300" --json $O/iso10360.json >/dev/null 2>&1; echo "10360 $?"
$V iso230-3 $E/drift_spindle.csv --json $O/drift.json >/dev/null 2>&1; echo "drift $?"
