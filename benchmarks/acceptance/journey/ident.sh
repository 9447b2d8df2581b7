#!/bin/bash
# byte-identity of valid runs' outputs: base 2932149 (before this branch's commits) vs HEAD
PY=/work/wt/journey/.venv/bin/python
EX=/work/wt/journey/_scratch/uf/ex
for tag in base head; do
  d=/work/wt/journey/_scratch/ident_$tag; rm -rf $d; mkdir -p $d; cd $d
  cp -r $EX/. .
  if [ $tag = base ]; then export PYTHONPATH=/work/wt/journey/_scratch/basepkg; else unset PYTHONPATH; fi
  rm -rf chk p c.json   # leftovers of earlier runs in the copied folder
  mkdir out
  $PY -m volerr calibrate DMU50 sphere_example_DMU50.csv --json out/c.json --errors-out out/ce --map-out out/m.csv > out/c.txt 2>&1
  $PY -m volerr calibrate MB1 ballbar/ballbar_XY.csv ballbar/ballbar_YZ.csv ballbar/ballbar_ZX.csv --json out/b.json > out/b.txt 2>&1
  $PY -m volerr calibrate MB1 ballplate_MB1.csv --parameters EXX,EYY,EZZ,EC0Y,EB0Z,EA0Z --degree 1 --json out/bp.json > out/bp.txt 2>&1
  $PY -m volerr loop MB1 deviations_MB1.csv --json out/l.json > out/l.txt 2>&1
  $PY -m volerr loop DMU50 drift:drift_spindle.csv --json out/s.json --predictions-out out/p.csv > out/s.txt 2>&1
  $PY -m volerr iso230-3 drift_spindle.csv --json out/i3.json > out/i3.txt 2>&1
  $PY -m volerr iso230-2 iso230_2_run_X.csv --json out/i2.json > out/i2.txt 2>&1
  $PY -m volerr drift convert drift_logger_raw.csv --out out/drift.csv --channel 'ch1=X at z=20' --channel 'ch2=Z' > out/dc.txt 2>&1
  $PY -m volerr ballbar evaluate ballbar_example_XY.csv --json out/bb.json > out/bb.txt 2>&1
  $PY -m volerr identify MB1 --axis X tracker_example_X.csv --out out/X.csv > out/id.txt 2>&1
  $PY -m volerr probe-cal probe_sphere.csv --sphere-radius 25.006 --out out/probe.csv --json out/probe.json > out/pc.txt 2>&1
  $PY -m volerr demo --only check plan --jobs 1 --out out/demo > out/demo.txt 2>&1
done
cd /work/wt/journey/_scratch
diff -r ident_base/out ident_head/out > ident_diff.txt; echo "diff rc=$?" >> ident_diff.txt
