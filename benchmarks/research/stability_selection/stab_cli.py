"""``volerr ARGS`` (``volerr.cli.main``) with the subsample selections of RULE.md beside it:
after a ``loop`` with ``--json J`` the file ``J.stab.json`` holds, per channel, the own
sources of the terms ``select.select_terms`` takes on every leave-one-blocked-fold-out
subsample (stab_runs.py's :func:`select_on`).  The simulators of
benchmarks/acceptance/issue44_independent/ run it in place of ``python -m volerr``
(stab_sims.py).

usage: python stab_cli.py loop LAYOUT drift:F ... --json J [...]
"""

from __future__ import annotations

import json
import os
import sys

from threadpoolctl import threadpool_limits

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import stab_runs  # noqa: E402
from volerr.cli import main as volerr_main  # noqa: E402
from volerr.loop.drift import fit  # noqa: E402


def main(argv) -> int:
    seen = []
    original = fit._channel

    def keep(ch, cols, Z, cands, cache):
        seen.append((ch, cols, Z, cands))
        return original(ch, cols, Z, cands, cache)

    fit._channel = keep
    try:
        code = volerr_main(argv)
    finally:
        fit._channel = original
    if code != 0 or "--json" not in argv or not seen:
        return code
    out = {}
    K = len(stab_runs.subsample_list(seen[0][0].fold))
    caches = [{} for _ in range(K)]
    with threadpool_limits(limits=1, user_api="blas"):
        for ch, cols, Z, cands in seen:
            label = next(k for k, v in ch.s.channels.items() if v is ch.y)
            subs = []
            for k, f in enumerate(stab_runs.subsample_list(ch.fold)):
                terms = stab_runs.select_on(ch, cols, Z, cands, f, caches[k])
                subs.append([stab_runs.source_key(cols, t["pair"][0]) for t in terms])
            out[label] = {"K": K, "fold_rule": ch.rule, "subsamples": subs}
    path = argv[argv.index("--json") + 1]
    with open(path + ".stab.json", "w") as fh:
        json.dump(out, fh, indent=1)
    return code


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
