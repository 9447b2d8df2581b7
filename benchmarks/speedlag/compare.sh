#!/bin/sh
# Byte comparison of two dumps of dump_outputs.py: every file but the raw loop reports
# (their wall time and paths differ; the normalised dayA.norm.json is compared).
# Prints the number of files compared and exits 1 on any difference.
set -e
a=$1; b=$2; n=0
for f in $(cd "$a" && find . -type f ! -name dayA.json | sort); do
    cmp "$a/$f" "$b/$f"
    n=$((n + 1))
done
[ "$(cd "$a" && find . -type f | wc -l)" = "$(cd "$b" && find . -type f | wc -l)" ]
echo "identical: $n files"
