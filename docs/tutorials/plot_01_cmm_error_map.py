"""
A CMM error map from error tables
=================================

Pahk's CMM A (layout ``MB1``): example error tables of its axes (``X.csv``, ``Y.csv``,
``Z.csv`` and ``constants.csv``; 'volerr formats tables') turned into error functions of
position, and the volumetric error (actual minus nominal probe tip, mm) over a plane of the
working volume.  The command: ``volerr map MB1 --errors errors_MB1``.
"""
import numpy as np
import matplotlib.pyplot as plt

import volerr
from volerr.cmm.examples import write_example_errors
from volerr.tables import ErrorFunctions
import tempfile

m = volerr.load("MB1")
folder = tempfile.mkdtemp()
write_example_errors(folder, "MB1")
funcs = ErrorFunctions.from_dir(folder, m)
print(m.axes, len(m.parameters), "parameters")

# %%
# The error on a 30 x 30 grid in the XY plane at mid Z, probe 100 mm below the quill.
(x0, x1), (y0, y1), (z0, z1) = (m.travel[a] for a in m.axes)
X, Y = np.meshgrid(np.linspace(x0, x1, 30), np.linspace(y0, y1, 30))
q = np.column_stack([X.ravel(), Y.ravel(), np.full(X.size, (z0 + z1) / 2)])
e = m.volumetric_error(q, funcs(q), probe=(0.0, 0.0, -100.0)) * 1e3   # um
fig, ax = plt.subplots(figsize=(6, 4.5))
c = ax.contourf(X, Y, np.linalg.norm(e, axis=1).reshape(X.shape), 20)
ax.quiver(X[::3, ::3], Y[::3, ::3], e[:, 0].reshape(X.shape)[::3, ::3],
          e[:, 1].reshape(X.shape)[::3, ::3])
fig.colorbar(c, label="|volumetric error| (µm)")
ax.set_xlabel("X (mm)")
ax.set_ylabel("Y (mm)")
ax.set_title("MB1: volumetric error at mid Z")

# %%
# The same through the API of ``volerr map`` (max components and RMS over a 9^3 grid, um):
res = volerr.error_map("MB1", folder, grid=9, probe=(0.0, 0.0, -100.0))
print(res.summary())
