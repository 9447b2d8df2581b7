"""Steps of a fit of the declared model shared by ``volerr loop`` and ``volerr calibrate``: the
held-out split, the degree of the component series by cross-validation, and the declared
model's columns (gauge fixed, what the data cannot separate reported).  Rows are readings of
any instrument (:class:`volerr.instruments.Observations`); deviations in mm."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import require
from . import blocks
from .design import (Problem, declared_design, gauge_mask, identifiability_gram, require_points,
                     rms, weakly_determined_gram)

DEGREE_CV_POINTS = 2500  # training points used to choose the degree (a random subset)


@dataclass
class Split:
    """Held-out split: ``test`` and ``train`` point indices, k-fold labels (None: LOO)."""

    train: np.ndarray
    test: np.ndarray
    folds: np.ndarray | None


def split_points(n: int, seed: int, test_fraction: float, folds: int | None) -> Split:
    rng = np.random.default_rng(seed)
    perm = rng.permutation(n)
    n_test = max(1, int(round(test_fraction * n)))
    test, train = np.sort(perm[:n_test]), np.sort(perm[n_test:])
    fold_t = None if folds is None else rng.permutation(len(train)) % folds
    return Split(train, test, fold_t)


def choose_degree(model, data, train, folds, ranges, max_degree, extra=None, weights=None,
                  parameters=None):
    """Degree of the component series by cross-validation on the training points (``extra``:
    effect columns (rows, m) included in every model compared; ``weights``: point weights;
    ``parameters``: the names fitted, None for all).  At most ``DEGREE_CV_POINTS`` random
    training points are used (the design is built for those only)."""
    keep, _ = gauge_mask(model, data, max_degree, ranges, parameters)
    if len(train) > DEGREE_CV_POINTS:  # the degree needs no more points than this
        sub = np.sort(np.random.default_rng(0).choice(len(train), DEGREE_CV_POINTS,
                                                      replace=False))
        if extra is not None:
            extra = extra.reshape(-1, 3, extra.shape[1])[train[sub]].reshape(-1, extra.shape[1])
        train, folds = train[sub], None
    elif extra is not None:
        extra = extra.reshape(-1, 3, extra.shape[1])[train].reshape(-1, extra.shape[1])
    sub_data = data.subset(train)
    design = declared_design(model, sub_data, max_degree, ranges)
    sw = np.ones(3 * len(train)) if weights is None else np.repeat(np.sqrt(weights[train]), 3)
    y = sub_data.deviation.ravel() * sw
    pts = np.arange(len(train))
    scores = {}
    for k in range(1, max_degree + 1):
        m = keep & np.array([lab[1] is None or lab[0] == "setup" or lab[1] <= k
                             for lab in design.labels])
        if 3 * len(train) < 2 * m.sum() + 10:
            break
        A = design.A[:, :, m].reshape(-1, m.sum())
        if extra is not None and extra.shape[1]:
            A = np.concatenate([A, extra], axis=1)
        prob = Problem(A * sw[:, None], y)
        scores[k] = rms(prob.loo_residuals(pts) if folds is None else
                        prob.cv_residuals(folds, pts))
        best_k = min(scores, key=scores.get)
        if k - best_k >= 2:   # two degrees without a gain: stop
            break
    require(scores, f"too few points for the basis: {len(train)} training points cannot fit "
            f"even a degree-1 model of layout {model.name}")
    best = min(scores.values())
    return min(k for k, v in scores.items() if v <= best), scores


@dataclass
class Declared:
    """The declared model's design at the data: columns kept after gauge fixing and what the
    plan cannot separate."""

    design: blocks.Design        # the kept columns, generated per block of points
    keep: np.ndarray
    gauge: list
    labels: list
    unidentifiable: list
    weak: list


def declared_step(model, dat, degree, ranges, train, parameters=None) -> Declared:
    """The declared model's columns on ``dat``: gauge fixed (:func:`gauge_mask`), then what the
    training points cannot separate dropped and reported (``parameters``: the names fitted,
    None for all)."""
    all_labels = declared_design(model, dat.subset(np.arange(1)), degree, ranges).labels
    keep, gauge = gauge_mask(model, dat, degree, ranges, parameters)
    require_points(len(train), int(keep.sum()), f"declared model of degree {degree}")
    labels = [lab for lab, k in zip(all_labels, keep) if k]
    G_tr, _, _ = blocks.normal(blocks.Design(model, dat, degree, ranges, keep), train,
                               np.ones(len(train)), dat.deviation.ravel())
    keep_d, unident = identifiability_gram(G_tr, labels)
    keep = keep.copy()
    keep[np.flatnonzero(keep)[~keep_d]] = False     # what these data cannot separate
    labels = [lab for lab, k in zip(all_labels, keep) if k]
    weak = weakly_determined_gram(G_tr[np.ix_(keep_d, keep_d)], labels)
    design = blocks.Design(model, dat, degree, ranges, keep)
    return Declared(design, keep, gauge, labels, unident, weak)


