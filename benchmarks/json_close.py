"""Compare two JSON documents numerically: every number equal within a relative tolerance
(default 1e-12, what issue 42 allows for the calibrate / loop / check JSON), everything else
(keys, strings, booleans, nulls, list lengths) identical.

    python benchmarks/json_close.py A.json B.json [--rtol 1e-12] [--ignore seconds,...]

A number pair ``a, b`` is equal when ``|a - b| <= rtol * max(|a|, |b|)`` (two zeros are equal;
integers and floats compare by value).  Keys named in ``--ignore`` (default ``seconds``: the
run's own duration) are skipped wherever they occur.  Prints every difference with its path
(``effects[0].evidence.delta_bic``) and the largest relative difference of the numbers that
differ at all; exit status 0 when the documents are equal within ``rtol``, 1 when not.
"""

from __future__ import annotations

import argparse
import json
import math
import sys


def differences(a, b, rtol: float, ignore=frozenset(), path: str = "") -> tuple[list, float]:
    """([(path, a, b, relative difference or None)] of the values that differ beyond
    ``rtol`` (None: not numbers or not the same shape), the largest relative difference of
    any two numbers that are not bitwise equal)."""
    if _number(a) and _number(b):
        if a == b or (math.isnan(a) and math.isnan(b)):
            return [], 0.0
        rel = abs(a - b) / max(abs(a), abs(b))
        return ([(path, a, b, rel)] if rel > rtol else []), rel
    if isinstance(a, dict) and isinstance(b, dict):
        if set(a) != set(b):
            return [(path + " keys", sorted(a), sorted(b), None)], 0.0
        out, worst = [], 0.0
        for k in a:
            if k in ignore:
                continue
            d, w = differences(a[k], b[k], rtol, ignore, f"{path}.{k}" if path else k)
            out, worst = out + d, max(worst, w)
        return out, worst
    if isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            return [(path + " length", len(a), len(b), None)], 0.0
        out, worst = [], 0.0
        for i, (x, y) in enumerate(zip(a, b)):
            d, w = differences(x, y, rtol, ignore, f"{path}[{i}]")
            out, worst = out + d, max(worst, w)
        return out, worst
    return ([] if a == b and type(a) is type(b) else [(path, a, b, None)]), 0.0


def _number(x) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("a")
    ap.add_argument("b")
    ap.add_argument("--rtol", type=float, default=1e-12)
    ap.add_argument("--ignore", default="seconds",
                    help="comma-separated keys skipped wherever they occur (default: seconds)")
    args = ap.parse_args(argv)
    with open(args.a, encoding="utf-8") as fa, open(args.b, encoding="utf-8") as fb:
        a, b = json.load(fa), json.load(fb)
    ignore = frozenset(k for k in args.ignore.split(",") if k)
    diffs, worst = differences(a, b, args.rtol, ignore)
    for path, x, y, rel in diffs:
        print(f"{path}: {x!r} != {y!r}" + ("" if rel is None else f" (relative {rel:.3g})"))
    verdict = "equal" if not diffs else f"{len(diffs)} difference(s)"
    print(f"{verdict} within {args.rtol:g} relative (ignored: {', '.join(sorted(ignore)) or '-'}); "
          f"largest relative difference of numbers not bitwise equal: {worst:.3g}")
    return 0 if not diffs else 1


if __name__ == "__main__":
    sys.exit(main())
