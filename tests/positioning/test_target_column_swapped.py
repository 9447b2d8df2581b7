"""An ISO 230-2 run (long format) whose target and deviation columns are exchanged is refused
naming the swap: every reading then has a target of its own, which no run can have (ISO
230-2:2014: every target read in both directions in every cycle).  Before, the line named
the first target read in one direction only, not the likely mistake."""

from __future__ import annotations

import numpy as np

from volerr.cli import main


def test_target_and_deviation_swapped_named(tmp_path, capsys):
    rng = np.random.default_rng(11)
    lines = ["deviation_um,cycle,direction,target_mm"]          # the two headers exchanged
    for t in (0.0, 200.0, 400.0, 600.0):
        for j in (1, 2, 3):
            for d in ("+1", "-1"):
                lines.append(f"{t:g},{j},{d},{0.01 * t + rng.normal(0.0, 0.5):.4f}")
    f = tmp_path / "run.csv"
    f.write_text("\n".join(lines) + "\n")
    out = tmp_path / "i.json"
    rc = main(["iso230-2", str(f), "--json", str(out)])
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 2 and len(err) == 1, err
    assert "run.csv" in err[0] and "target and deviation columns swapped" in err[0], err[0]
    assert not out.exists()


def test_unswapped_run_is_read(tmp_path, capsys):
    rng = np.random.default_rng(11)
    lines = ["target_mm,cycle,direction,deviation_um"]
    for t in (0.0, 200.0, 400.0, 600.0):
        for j in (1, 2, 3):
            for d in ("+1", "-1"):
                lines.append(f"{t:g},{j},{d},{0.01 * t + rng.normal(0.0, 0.5):.4f}")
    f = tmp_path / "run.csv"
    f.write_text("\n".join(lines) + "\n")
    assert main(["iso230-2", str(f), "--json", str(tmp_path / "i.json")]) == 0
