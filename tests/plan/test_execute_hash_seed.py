"""A plan executed on the model writes the same readings whatever Python's string hashing
(``PYTHONHASHSEED``): the random draws per station and per placement are handed out in the
labels' sorted order, not a set's iteration order (a set of strings iterates in an order that
changes with the hash seed, so ``plan_MB1/distances.csv`` of ``volerr demo`` once changed from
run to run)."""

import os
import subprocess
import sys

HEADER = "X,Y,Z,Xp,Yp,Zp,station,d_mm,station_x,station_y,station_z,u_um"
STATIONS = {"T9": (450, -28.8, 0), "T10": (450, -28.8, 200), "T14": (450, 603.8, 200),
            "T13": (450, 603.8, 0), "A2": (-50, 300, 100)}
SCRIPT = ("import sys, numpy as np, volerr; from volerr.plan import execute; "
          "execute(sys.argv[1], volerr.load('MB1'), {}, np.random.default_rng(7))")


def _plan(path):
    rows = [f"{x},{y},{z},0,0,0,{s},,{sx},{sy},{sz},0.4"
            for s, (sx, sy, sz) in STATIONS.items()
            for x, y, z in ((90, 57.5, 40), (450, 300, 200), (810, 542.5, 360))]
    path.write_text("# volerr plan: layout MB1, distances\n" + HEADER + "\n"
                    + "\n".join(rows) + "\n", encoding="utf-8")


def test_executed_readings_do_not_depend_on_the_hash_seed(tmp_path):
    out = []
    for seed in ("0", "1", "2"):
        path = tmp_path / f"distances_{seed}.csv"
        _plan(path)
        env = {**os.environ, "PYTHONHASHSEED": seed}
        subprocess.run([sys.executable, "-c", SCRIPT, str(path)], check=True, env=env)
        out.append(path.read_bytes())
    filled = [ln.split(",")[7] for ln in out[0].decode().splitlines()[2:]]
    assert all(filled) and len(set(filled)) == len(filled)      # every reading written
    assert out[0] == out[1] == out[2]
