"""A material temperature column (``T_C``) of a laser-interferometer run in degF or K is
refused (one line naming the file, the column and the likely unit; nothing written), as
``--material-temp-C`` already was: the correction to 20 degC (ISO 1; ISO 230-2:2014) would
otherwise move every deviation by cte x (T - 20) x P -- 48 K on 900 mm of steel is ~500 um.
A long-format run read by ``volerr calibrate`` (section ``interferometer``) that reads one
target, cycle and direction twice (a block pasted twice) is refused as ``volerr iso230-2``
refuses it, and so is a positioning reading of 1 mm or more (nm under the um header)."""

from __future__ import annotations

import numpy as np
import pytest

from volerr.cli import main

TARGETS = np.arange(0.0, 901.0, 112.5)     # 9 targets over MB1's X travel 0 .. 900 mm


def run_rows(T=None, seed=5):
    """Rows of a long-format run (5 cycles, both directions), deviations um, fixed seed."""
    rng = np.random.default_rng(seed)
    rows = []
    for t in TARGETS:
        for j in range(5):
            for word, rev in (("+1", 1.0), ("-1", -1.0)):
                dev = 0.004 * t + 1.2 * rev + rng.normal(0.0, 0.3)
                rows.append([f"{t:g}", str(j + 1), word, f"{dev:.4f}"]
                            + ([f"{T:g}"] if T is not None else []))
    return rows


def write(path, rows, T=False, header=()):
    head = "target_mm,cycle,direction,deviation_um" + (",T_C" if T else "")
    path.write_text("".join(h + "\n" for h in header) + head + "\n"
                    + "".join(",".join(r) + "\n" for r in rows))
    return path


def write_wide(path, T):
    rng = np.random.default_rng(7)
    lines = ["target_mm," + ",".join(f"fwd_{j}_um,bwd_{j}_um" for j in (1, 2, 3)) + ",T_C"]
    for t in TARGETS:
        vals = [f"{0.004 * t + rng.normal(0.0, 0.3):.4f}" for _ in range(6)]
        lines.append(f"{t:g}," + ",".join(vals) + f",{T:g}")
    path.write_text("\n".join(lines) + "\n")
    return path


def refused_one_line(capsys, rc, *words):
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 2 and len(err) == 1, err
    for w in words:
        assert w in err[0], err[0]
    return err[0]


@pytest.mark.parametrize("T, likely", [(68.4, "degF"), (293.55, "in K")])
def test_iso230_2_material_temperature_not_degC_refused(tmp_path, capsys, T, likely):
    f = write(tmp_path / "run.csv", run_rows(T), T=True)
    out = tmp_path / "out.json"
    rc = main(["iso230-2", str(f), "--cte-ppm-per-K", "11.5", "--json", str(out)])
    refused_one_line(capsys, rc, "run.csv", "column T_C", likely)
    assert not out.exists()


def test_iso230_2_wide_material_temperature_degF_refused(tmp_path, capsys):
    f = write_wide(tmp_path / "wide.csv", 71.0)
    rc = main(["iso230-2", str(f), "--cte-ppm-per-K", "11.5", "--json", str(tmp_path / "o.json")])
    refused_one_line(capsys, rc, "wide.csv", "column T_C", "degF")


def test_iso230_2_material_temperature_in_degC_still_corrected(tmp_path, capsys):
    f = write(tmp_path / "run.csv", run_rows(23.5), T=True)
    out = tmp_path / "out.json"
    assert main(["iso230-2", str(f), "--cte-ppm-per-K", "11.5", "--json", str(out)]) == 0
    assert out.exists()


def test_interferometer_material_temperature_degF_refused(tmp_path, capsys):
    f = write(tmp_path / "lx.csv", run_rows(68.0), T=True, header=["# axis: X", "# u_um: 1"])
    out = tmp_path / "cal.json"
    rc = main(["calibrate", "MB1", str(f), "--json", str(out)])
    refused_one_line(capsys, rc, "lx.csv", "column T_C", "degF")
    assert not out.exists()


def test_interferometer_reading_given_twice_refused(tmp_path, capsys):
    rows = run_rows()
    head = ["# axis: X", "# u_um: 1"]
    ok = write(tmp_path / "ok.csv", rows, header=head)
    assert main(["calibrate", "MB1", str(ok), "--json", str(tmp_path / "ok.json")]) == 0
    capsys.readouterr()
    f = write(tmp_path / "lx.csv", rows + rows[:4], header=head)
    out = tmp_path / "cal.json"
    rc = main(["calibrate", "MB1", str(f), "--json", str(out)])
    line = refused_one_line(capsys, rc, "lx.csv", "pasted twice")
    assert "cycle 1" in line and "target 0 mm" in line
    assert not out.exists()


def test_interferometer_reading_in_nm_refused_naming_the_unit(tmp_path, capsys):
    """A positioning reading of 1 mm or more (nm under the um header) is refused by the
    unit check ``volerr iso230-2`` holds the same file to, not only by the fit's residual."""
    rows = [r[:3] + [f"{float(r[3]) * 1000:.1f}"] for r in run_rows()]
    f = write(tmp_path / "lx.csv", rows, header=["# axis: X", "# u_um: 1"])
    out = tmp_path / "cal.json"
    rc = main(["calibrate", "MB1", str(f), "--json", str(out)])
    refused_one_line(capsys, rc, "lx.csv", "column deviation_um", "nm under a um header")
    assert not out.exists()
