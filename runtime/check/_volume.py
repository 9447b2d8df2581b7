"""The working volume of a check: the reference's parameter columns of the tool point's
volumetric error over the grid of :func:`volerr.plan._information.grid` (every linear axis in
5 steps over its travel, every rotary axis in 5 steps, at most one turn; the tool offset of
the check's files), and what a change of the parameters does there.

Units: columns in mm per report unit of the parameter (um, urad, um/mm ...); results um.
"""

from __future__ import annotations

import numpy as np

from ..estimate import blocks
from ..estimate.design import parameter_labels
from ..instruments import Observations
from ..plan._information import grid


def grid_columns(model, ref, tool) -> np.ndarray:
    """(p, 3, n) the volumetric error's column of each reference parameter (its order) at the
    grid poses, mm per report unit."""
    pos, probe = grid(model, tool)
    n = len(probe)
    obs = Observations(pos, probe, np.zeros((n, 3)), {c: np.zeros(n) for c in model.covariates})
    labels = ref.labels(model)
    keep = np.concatenate([np.zeros(len(obs.setup_labels), bool),
                           np.array([lab in labels for lab in parameter_labels(model,
                                                                               ref.degree)])])
    design = blocks.Design(model, obs, ref.degree, ref.ranges, keep)
    order = [design.labels.index(lab) for lab in labels]
    At = design.block(np.arange(n)).reshape(design.p, 3, n)[order]
    return At / ref.factors(model)[:, None, None]


def change_um(J: np.ndarray, delta) -> dict:
    """``{"max", "rms"}`` (um) of the length of the volumetric change ``sum_j J_j delta_j``
    (``delta`` (p,) report units) over the grid."""
    e = 1e3 * np.einsum("pcn,p->cn", J, np.asarray(delta, float))
    length = np.linalg.norm(e, axis=0)
    return {"max": round(float(length.max()), 4) if length.size else 0.0,
            "rms": round(float(np.sqrt(np.mean(length ** 2))), 4) if length.size else 0.0}


def map_max(J: np.ndarray, values, cov) -> tuple[float, float]:
    """(largest length of the volumetric error over the grid (um), its standard uncertainty
    there (um, along the error's direction)) of parameters ``values`` with covariance
    ``cov`` (report units)."""
    e = 1e3 * np.einsum("pcn,p->cn", J, np.asarray(values, float))
    length = np.linalg.norm(e, axis=0)
    k = int(np.argmax(length))
    u = e[:, k] / max(float(length[k]), 1e-300)
    g = 1e3 * np.einsum("pc,c->p", J[:, :, k], u)
    return float(length[k]), float(np.sqrt(max(g @ cov @ g, 0.0)))


def per_unit_max(J: np.ndarray) -> np.ndarray:
    """(p,) the largest length over the grid of each parameter's column (um per report
    unit): a change of ``D / per_unit_max`` moves the volumetric error by ``D`` um
    somewhere."""
    return 1e3 * np.linalg.norm(J, axis=1).max(axis=1)
