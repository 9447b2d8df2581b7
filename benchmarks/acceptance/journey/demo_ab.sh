#!/bin/bash
# interleaved: HEAD vs 00b7f79 (the README's timing commit), whole demo --jobs 1, CPU and wall
PY=/work/wt/journey/.venv/bin/python
for i in 1 2; do
  for tag in head old; do
    d=$(mktemp -d /tmp/demoab_XXXX)
    if [ $tag = old ]; then export PYTHONPATH=/work/wt/journey/_scratch/oldpkg; else unset PYTHONPATH; fi
    l=$(cut -d' ' -f1 /proc/loadavg)
    /usr/bin/time -f "$tag run$i load_before $l wall %e user %U sys %S" $PY -m volerr demo --out $d/o --jobs 1 > $d/out.txt 2>> /work/wt/journey/_scratch/demo_ab.txt
    echo "rc=$?" >> /work/wt/journey/_scratch/demo_ab.txt
    rm -rf $d
  done
done
