"""
A new machine: from a TOML file to derived code and its audit
=============================================================

A machine is one layout file.  Here a moving-bridge CMM with a longer X travel than Pahk's
CMM A, written from scratch: ``volerr derive my_cmm.toml`` derives its kinematic error model
with sympy and generates a numpy module (the file's header names the generator and a hash
of the layout); ``volerr.load("my_cmm.toml")`` uses it.  Its chain is MB1's, so its
volumetric error must be MB1's at every position inside both travels -- an independent check
of the derivation.  The audit compares derived equations with printed ones: for a new machine
nothing is printed, so the audit shown is that of MB1, the documented machine of the same
chain (``volerr audit MB1``).
"""
import json
import subprocess
import sys
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

import volerr

LAYOUT = '''
name = "MY_CMM"
kind = "cmm"
description = "moving bridge CMM: the bridge along Y, the carriage X on it, the ram Z"

[axes.X]
kind = "linear"
direction = [1, 0, 0]
travel = [0, 1200]

[axes.Y]
kind = "linear"
direction = [0, 1, 0]
travel = [0, 575]

[axes.Z]
kind = "linear"
direction = [0, 0, 1]
travel = [0, 400]

[chain]
tool = ["Y", "X", "Z"]
workpiece = []

[squareness]
EC0Y = "X"
EB0Z = "Z"
EA0Z = "Z"
'''
folder = Path(tempfile.mkdtemp())
path = folder / "my_cmm.toml"
path.write_text(LAYOUT)
out = subprocess.run([sys.executable, "-m", "volerr", "derive", str(path), "--out",
                      str(folder / "gen")], capture_output=True, text=True, check=True)
print(out.stdout)
print("\n".join((folder / "gen" / "my_cmm.py").read_text().splitlines()[:8]))

# %%
# The derived model against MB1's at random positions and errors.
mine, mb1 = volerr.load(str(path)), volerr.load("MB1")
rng = np.random.default_rng(0)
q = rng.uniform([0, 0, 0], [900, 575, 400], (200, 3))
errors = {p: rng.normal(0, 1e-5, 200) for p in mb1.parameters}
e1 = mine.volumetric_error(q, errors, probe=(0, 0, -50))
e2 = mb1.volumetric_error(q, errors, probe=(0, 0, -50))
print("largest difference:", np.abs(e1 - e2).max(), "mm")

# %%
# The audit of MB1: verdict counts per category.
out = subprocess.run([sys.executable, "-m", "volerr", "audit", "MB1", "--json",
                      str(folder / "audit.json")], capture_output=True, text=True, check=True)
print(out.stdout.strip().splitlines()[-1])
verdicts = json.loads((folder / "audit.json").read_text())
cats = {}
for v in verdicts:
    cats[v["category"]] = cats.get(v["category"], 0) + 1
fig, ax = plt.subplots(figsize=(6, 2.5))
ax.barh(list(cats), list(cats.values()))
ax.set_xlabel("verdicts of volerr audit MB1")
