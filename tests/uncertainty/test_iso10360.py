"""Simulated ISO 10360-2 length test against hand computations."""

from __future__ import annotations

import json

import numpy as np

import volerr
from volerr.cli import main
from volerr.tables import ErrorTable, write_error_dir
from volerr.uncertainty import iso10360

MB1 = volerr.load("MB1")


def test_geometry_is_the_standards():
    t = iso10360.length_test(MB1)
    assert t.targets.shape == (7, 5, 2, 3) and t.repetitions == 3
    centre = np.array([450.0, 287.5, 200.0])
    mid = t.targets.mean(axis=2)
    assert np.allclose(mid, centre)
    # 4 space diagonals of the 900 x 575 x 400 box, then X, Y, Z
    diag = np.linalg.norm([900, 575, 400])
    assert np.allclose(t.lengths[:4, -1], 0.7 * diag)
    assert np.allclose(t.lengths[4:, -1], 0.7 * np.array([900, 575, 400]))
    assert t.lengths[:4, -1].min() >= 0.66 * diag


def test_pure_scale_error_gives_s_times_L(tmp_path, capsys):
    """EXX = s X: the X line reads E = -s L; a diagonal -s L ux^2; Y and Z lines 0."""
    s = 12e-6
    nodes = np.linspace(0, 900, 4)
    write_error_dir(tmp_path / "err", {"X": ErrorTable("X", nodes, {"EXX": s * nodes})})
    out = tmp_path / "e.json"
    assert main(["iso10360", "MB1", "--errors", str(tmp_path / "err"), "--json", str(out),
                 "--mpe", "E0=3+L/100", "--plot", str(tmp_path / "e.png")]) == 0
    doc = json.loads(out.read_text())
    t = iso10360.length_test(MB1)
    for i, pos in enumerate(doc["positions"]):
        L = np.array(pos["lengths_mm"])
        E = np.array(pos["E_um"])
        ux = t.u[i, 0]
        assert np.allclose(E, (-s * L * ux ** 2 * 1e3)[:, None], atol=1e-4), pos["line"]
    assert doc["positions"][4]["line"] == "axis X"
    assert abs(doc["max_abs_E_um"] - s * 630 * 1e3) < 1e-3
    assert doc["passes"] is True
    assert (tmp_path / "e.png").stat().st_size > 1000
