#!/bin/bash
# usage: TREES=DIR ab_bench.sh ROUNDS TREE... (DIR/TREE/pkg/volerr -> that tree's runtime/); bench --drift per tree alternated; prints tree, loop CPU, process user+sys
cd "$(dirname "$0")/../.."
R=$1; shift
for r in $(seq $R); do for t in "$@"; do
  out=$( { PYTHONPATH=$TREES/$t/pkg /usr/bin/time -f "TIME %U %S %e" .venv/bin/python benchmarks/bench_loop.py --drift; } 2>&1 )
  loop=$(echo "$out" | grep -o "channels: [0-9.]* s CPU" | grep -o "[0-9.]* s" | head -1)
  tm=$(echo "$out" | grep "^TIME")
  echo "round $r tree $t loop_cpu $loop proc $tm $(date -u +%H:%M:%S)"
done; done
