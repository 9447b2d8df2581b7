#!/bin/bash
# usage: run77.sh OUTDIR   (the 77 fits of the independent check; results out_*.txt in OUTDIR)
O=$1; mkdir -p $O; export ACCEPT44_OUT=$O
REPO=$(cd "$(dirname "$0")/../../.." && pwd)
D=$REPO/benchmarks/acceptance/issue44_independent
PY=${PY:-$REPO/.venv/bin/python}
for v in easy hard; do p=s1; [ $v = hard ] && p=s1h
  for s in 1 2 3; do for dt in 15 60; do S1_VARIANT=$v $PY $D/a44_scen1.py $s $dt > $O/out_${p}_seed${s}_dt${dt}.txt 2>$O/err_${p}_${s}_${dt}.txt; done; done; done
for s in 1 2 3 4 5 6 7 8; do for dt in 15 60; do S1_VARIANT=speedonly $PY $D/a44_scen1.py $s $dt > $O/out_s1s_seed${s}_dt${dt}.txt 2>$O/err_s1s_${s}_${dt}.txt; done; done
for v in base constonly env3; do for s in 1 2 3; do S2_VARIANT=$v $PY $D/a44_scen2.py $s > $O/out_s2${v}_seed${s}.txt 2>$O/err_s2${v}_${s}.txt; done; done
for sc in 3 4; do for s in 1 2 3; do $PY $D/a44_scen34.py $sc $s > $O/out_s${sc}_seed${s}.txt 2>$O/err_s${sc}_${s}.txt; done; done
cd $O && $PY $D/summary.py > table.md
echo ALLDONE
