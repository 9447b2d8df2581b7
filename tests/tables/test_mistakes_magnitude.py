"""Error tables in the wrong unit: refused from the machine's size (volerr.tables.plausible).

Each mistake is a technician's: a column headed ``_mm`` over values in um, ``_rad`` over urad,
arcsec or deg, a squareness in urad declared ``rad``, a location error in um declared ``mm``.
Each run of ``volerr map`` / ``volerr diagonals`` (in-process) must exit 2 with one line on
stderr naming the file, the column and the likely unit, write nothing and leave the inputs
alone.  The limits are derived here from the layout's travel and the stated rule
(translational 500 um + 500 ppm of the largest linear travel; angular min(1 mrad,
sqrt(2 x 0.5 um / L))), not read from the code.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import volerr
from volerr.cli import main
from volerr.errors import InputError
from volerr.tables import ErrorFunctions, ErrorTable, read_error_dir, write_error_dir

X = np.linspace(0.0, 900.0, 10)        # MB1's X travel is 0 .. 900 mm


def _size_mm(layout: str) -> float:
    model = volerr.load(layout)
    return max(hi - lo for a, (lo, hi) in model.travel.items() if a not in model.rotary_axes)


def _limits(layout: str) -> tuple[float, float]:
    """(translational um, angular urad) of the stated rule."""
    size = _size_mm(layout)
    return 500.0 + 500e-6 * size * 1e3, min(1000.0, math.sqrt(2 * 0.5e-3 / size) * 1e6)


def _table(d, axis, header, columns):
    rows = [",".join(header)] + [",".join(f"{v:.6g}" for v in row) for row in zip(*columns)]
    (d / f"{axis}.csv").write_text("\n".join(rows) + "\n")


def _errors(tmp_path, x_header=("X", "EXX_um", "EAX_urad"), x_cols=None, constants=None):
    """An error directory of MB1: X.csv (small smooth errors unless given) and constants."""
    d = tmp_path / "errors"
    d.mkdir()
    cols = x_cols or [X, 3.0 * np.sin(X / 300.0), 4.0 * X / 900.0]
    _table(d, "X", x_header, cols)
    lines = ["name,value,unit"] + [",".join(map(str, c)) for c in (constants or
                                   [("EC0Y", 14.1, "urad")])]
    (d / "constants.csv").write_text("\n".join(lines) + "\n")
    return d


def _refused(tmp_path, capsys, d, *needles, command="map", layout="MB1"):
    """Run the command on ``d``; exit 2, one stderr line with every needle, nothing written,
    the inputs unchanged."""
    before = {p.name: p.read_bytes() for p in d.iterdir()}
    out, js = tmp_path / "map.csv", tmp_path / "s.json"
    args = [command, layout, "--errors", str(d), "--json", str(js)]
    if command == "map":
        args += ["--out", str(out), "--grid", "3"]
    code = main(args)
    err = capsys.readouterr().err
    assert code == 2, err
    assert err.count("\n") == 1 and "Traceback" not in err, err
    for n in needles:
        assert n in err, (n, err)
    assert "--accept-implausible" in err
    assert not out.exists() and not js.exists()
    assert {p.name: p.read_bytes() for p in d.iterdir()} == before
    return err


def test_the_limits_follow_the_stated_rule():
    """MB1: the largest linear travel 900 mm -> 950 um and 1000 urad; a 5 m machine allows
    more translation and less angle (the small-angle model's dropped term e^2 L / 2)."""
    from volerr.tables import plausible

    lim = plausible.limits_for(volerr.load("MB1"))
    assert lim.length_mm * 1e3 == pytest.approx(_limits("MB1")[0])
    assert lim.angle_rad * 1e6 == pytest.approx(_limits("MB1")[1])
    big = plausible.Limits(5000.0, "5 m")
    assert big.length_mm * 1e3 == pytest.approx(3000.0)
    assert big.angle_rad == pytest.approx(math.sqrt(1e-3 / 5000.0))
    assert big.angle_rad ** 2 * 5000.0 / 2 == pytest.approx(0.5e-3)    # 0.5 um dropped


def test_mm_header_over_um_values(tmp_path, capsys):
    """The issue's case: EXX_mm over um values (a map of thousands of um)."""
    d = _errors(tmp_path, ("X", "EXX_mm", "EAX_urad"),
                [X, 5.606 * X / 900.0, 4.0 * X / 900.0])
    err = _refused(tmp_path, capsys, d, "X.csv", "EXX_mm", "likely in um", "5606 um",
                   f"limit {_limits('MB1')[0]:.0f} um")


def test_mm_header_over_nm_values(tmp_path, capsys):
    d = _errors(tmp_path, ("X", "EYX_mm", "EAX_urad"),
                [X, 2500.0 * np.sin(X / 200.0), 4.0 * X / 900.0])
    _refused(tmp_path, capsys, d, "X.csv", "EYX_mm", "likely in nm")


def test_um_header_over_nm_values(tmp_path, capsys):
    d = _errors(tmp_path, ("X", "EZX_um", "EAX_urad"),
                [X, 1800.0 * X / 900.0, 4.0 * X / 900.0])
    _refused(tmp_path, capsys, d, "X.csv", "EZX_um", "likely in nm, not um")


def test_rad_header_over_urad_values(tmp_path, capsys):
    d = _errors(tmp_path, ("X", "EXX_um", "EAX_rad"),
                [X, 3.0 * np.sin(X / 300.0), 12.5 * X / 900.0])
    _refused(tmp_path, capsys, d, "X.csv", "EAX_rad", "likely in urad")


def test_rad_header_over_arcsec_values(tmp_path, capsys):
    d = _errors(tmp_path, ("X", "EXX_um", "EBX_rad"),
                [X, 3.0 * np.sin(X / 300.0), 6.0 * np.cos(X / 400.0)])
    _refused(tmp_path, capsys, d, "X.csv", "EBX_rad", "arcsec", "converted")


def test_rad_header_over_degree_values(tmp_path, capsys):
    """0.004 deg (70 urad) written under _rad: 4 mrad, beyond 1 mrad; deg is named."""
    d = _errors(tmp_path, ("X", "EXX_um", "ECX_rad"),
                [X, 3.0 * np.sin(X / 300.0), 0.004 * X / 900.0])
    _refused(tmp_path, capsys, d, "X.csv", "ECX_rad", "deg")


def test_translational_values_in_an_angular_column(tmp_path, capsys):
    """Positions (0 .. 900) pasted into an angular column: no usual unit makes them an
    angular error."""
    d = _errors(tmp_path, ("X", "EXX_um", "EAX_urad"), [X, 3.0 * np.sin(X / 300.0), X * 10])
    _refused(tmp_path, capsys, d, "X.csv", "EAX_urad", "another quantity")


def test_uncertainty_column_in_mm_over_um(tmp_path, capsys):
    d = _errors(tmp_path, ("X", "EXX_um", "EXX_std_mm"),
                [X, 3.0 * np.sin(X / 300.0), np.full(X.size, 1.2)])
    _refused(tmp_path, capsys, d, "X.csv", "EXX_std_mm", "likely in um")


def test_reversal_column_in_mm_over_um(tmp_path, capsys):
    d = _errors(tmp_path, ("X", "EXX_um", "RV_X_mm"),
                [X, 3.0 * np.sin(X / 300.0), np.full(X.size, 2.5)])
    _refused(tmp_path, capsys, d, "X.csv", "RV_X_mm", "likely in um")


def test_squareness_in_urad_declared_rad(tmp_path, capsys):
    d = _errors(tmp_path, constants=[("EC0Y", 14.1, "rad")])
    _refused(tmp_path, capsys, d, "constants.csv:2", "EC0Y = 14.1 rad", "likely in urad")


def test_squareness_in_degrees_declared_rad(tmp_path, capsys):
    """-0.0035 deg (61 urad) given as rad: the sign is kept, deg is named."""
    d = _errors(tmp_path, constants=[("EC0Y", 14.1, "urad"), ("EB0Z", -0.0035, "rad")])
    _refused(tmp_path, capsys, d, "constants.csv:3", "EB0Z = -0.0035 rad", "deg")


def test_squareness_in_urad_declared_rad_through_diagonals(tmp_path, capsys):
    d = _errors(tmp_path, constants=[("EA0Z", -32, "rad")])
    _refused(tmp_path, capsys, d, "EA0Z", "likely in urad", command="diagonals")


def test_mm_header_over_um_values_through_diagonals(tmp_path, capsys):
    d = _errors(tmp_path, ("X", "EXX_mm"), [X, 2.0 + X / 450.0])
    _refused(tmp_path, capsys, d, "EXX_mm", "likely in um", command="diagonals")


def test_location_error_in_um_declared_mm_on_a_five_axis_machine(tmp_path, capsys):
    """DMU50 (largest linear travel from its layout): EX0C = 12 'mm' is 12 um."""
    d = tmp_path / "errors"
    d.mkdir()
    (d / "constants.csv").write_text("name,value,unit\nEX0C,12,mm\n")
    lim = _limits("DMU50")[0]
    _refused(tmp_path, capsys, d, "EX0C = 12 mm", "likely in um", f"limit {lim:.0f} um",
             layout="DMU50")


def test_accept_implausible_uses_the_values(tmp_path, capsys):
    """--accept-implausible: the same table is used as written (the map shows 5.6 mm)."""
    d = _errors(tmp_path, ("X", "EXX_mm"), [X, 5.606 * X / 900.0])
    js = tmp_path / "s.json"
    assert main(["map", "MB1", "--errors", str(d), "--grid", "3", "--json", str(js),
                 "--accept-implausible"]) == 0
    capsys.readouterr()
    s = json.loads(js.read_text())
    text = json.dumps(s)
    assert "5606" in text or any(abs(v - 5606.0) < 1.0 for v in _numbers(s)), text[:400]


def _numbers(obj):
    if isinstance(obj, dict):
        for v in obj.values():
            yield from _numbers(v)
    elif isinstance(obj, list):
        for v in obj:
            yield from _numbers(v)
    elif isinstance(obj, (int, float)) and not isinstance(obj, bool):
        yield float(obj)


def test_shipped_example_tables_are_accepted(tmp_path):
    """The demo's example error directories stay accepted (values far inside the limits)."""
    from volerr.cmm.examples import write_example_errors

    for layout in ("MB1", "MH2"):
        d = tmp_path / layout
        write_example_errors(d, layout)
        ErrorFunctions.from_dir(d, layout)


def test_python_api_reader_and_writer(tmp_path):
    """read_error_dir / ErrorFunctions.from_dir refuse or accept as asked; write_error_dir
    refuses an absurd identified table before writing anything."""
    d = _errors(tmp_path, ("X", "EXX_mm"), [X, 5.606 * X / 900.0])
    model = volerr.load("MB1")
    with pytest.raises(InputError, match="EXX_mm.*likely in um"):
        read_error_dir(d, machine=model)
    with pytest.raises(InputError, match="EXX_mm"):
        ErrorFunctions.from_dir(d, model)
    funcs = ErrorFunctions.from_dir(d, model, accept_implausible=True)
    assert funcs({"X": [900.0], "Y": [0.0], "Z": [0.0]})["EXX"][0] == pytest.approx(5.606)
    out = tmp_path / "identified"
    absurd = ErrorTable("X", X, {"EXX": 2e-3 * X})                 # 1.8 mm at 900 mm
    with pytest.raises(InputError, match="not written"):
        write_error_dir(out, {"X": absurd}, {"EC0Y": 20e-6}, machine=model)
    assert not out.exists() or not any(out.iterdir())
    write_error_dir(out, {"X": absurd}, machine=model, accept_implausible=True)
    assert (out / "X.csv").exists()
