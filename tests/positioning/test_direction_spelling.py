"""The direction of an ISO 230-2 reading written as a spreadsheet writes a number, ``1.0`` /
``-1.0``, is +1 / -1 (as the cycle ``1.0`` is cycle 1): such a run can be right and is read,
with the figures of the same run written ``+1`` / ``-1``."""

from __future__ import annotations

import json

import numpy as np

from volerr.cli import main


def write(path, plus, minus):
    rng = np.random.default_rng(2)
    lines = ["target_mm,cycle,direction,deviation_um"]
    for t in (0.0, 250.0, 500.0):
        for j in (1, 2):
            for d in (plus, minus):
                lines.append(f"{t:g},{j},{d},{0.01 * t + rng.normal(0.0, 0.5):.4f}")
    path.write_text("\n".join(lines) + "\n")
    return path


def test_direction_as_float_numbers_read_as_signs(tmp_path, capsys):
    a = write(tmp_path / "a.csv", "+1", "-1")
    b = write(tmp_path / "b.csv", "1.0", "-1.0")
    assert main(["iso230-2", str(a), "--json", str(tmp_path / "a.json")]) == 0
    assert main(["iso230-2", str(b), "--json", str(tmp_path / "b.json")]) == 0, \
        capsys.readouterr().err
    ja, jb = (json.loads((tmp_path / f"{k}.json").read_text()) for k in "ab")
    for key in ("A_um", "B_um", "E_um", "R_um", "M_um"):
        assert ja[key] == jb[key], key
