"""The 77 fits of benchmarks/acceptance/issue44_independent/ (the seeds and variants of its
table_after_session6.md) run again with stab_cli.py in place of ``python -m volerr``, so
that every loop JSON has its subsample selections beside it (``J.stab.json``).  Outputs in
out/sims/ (the scenario scripts' files and JSONs); then stab_sims_compare.py.

usage: python stab_sims.py
"""

from __future__ import annotations

import json
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(os.path.dirname(HERE)))
os.environ["ACCEPT44_OUT"] = os.path.join(HERE, "out", "sims")
sys.path.insert(0, os.path.join(ROOT, "benchmarks", "acceptance", "issue44_independent"))

import a44_sim as sim  # noqa: E402

sim.VOLERR_CMD = [sys.executable, os.path.join(HERE, "stab_cli.py")]

import a44_scen1 as scen1  # noqa: E402
import a44_scen2 as scen2  # noqa: E402
import a44_scen34 as scen34  # noqa: E402


def main():
    os.makedirs(sim.OUT, exist_ok=True)
    done = []
    for variant, seeds in (("easy", (1, 2, 3)), ("hard", (1, 2, 3)),
                           ("speedonly", tuple(range(1, 9)))):
        scen1.VARIANT = variant
        for seed in seeds:
            for dt in (15.0, 60.0):
                done += [r["tag"] for r in scen1.evaluate(seed, dt)]
                print(done[-2:], flush=True)
    scen1.VARIANT = "easy"            # scenarios 3 and 4 are built on scenario 1's sensors
    for scen in (3, 4):
        for seed in (1, 2, 3):
            done += [r["tag"] for r in scen34.evaluate(scen, seed)]
            print(done[-2:], flush=True)
    for variant in ("base", "constonly", "env3"):
        scen2.VARIANT = variant
        for seed in (1, 2, 3):
            done.append(scen2.evaluate(seed)["tag"])
            print(done[-1:], flush=True)
    json.dump(done, open(os.path.join(sim.OUT, "tags.json"), "w"), indent=1)
    print(len(done), "fits")


if __name__ == "__main__":
    main()
