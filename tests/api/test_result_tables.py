"""``table()`` holds the numbers the command prints, recomputed here independently (issue 42
item 5: ``ErrorMap.table()`` was empty): the map's maxima from the model and the error
functions on the same grid; the ISO 230-3 ranges from the drift file's columns; the
diagonals' dL from the end points' volumetric errors (first order: dL = u . (e(b) - e(a)))."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

import volerr


@pytest.fixture(scope="module")
def ex(tmp_path_factory):
    from volerr.cmm.examples import write_example_errors
    from volerr.example_files import write_drift_examples

    d = tmp_path_factory.mktemp("tables")
    write_example_errors(d / "errors_MB1", "MB1")
    write_drift_examples(d)
    return d


def _records(table) -> dict:
    rows = table.to_dict("records") if hasattr(table, "to_dict") else \
        [r._asdict() for r in table]
    return {r["name"]: r for r in rows}


def test_the_map_table_is_the_grids_maxima(ex):
    from volerr.tables.functions import ErrorFunctions

    model = volerr.load("MB1")
    funcs = ErrorFunctions.from_dir(ex / "errors_MB1", model)
    ticks = [np.linspace(*model.travel[a], 4) for a in ("X", "Y", "Z")]
    q = np.array(list(itertools.product(*ticks)))
    e = model.volumetric_error(q, funcs(q)) * 1e3          # um
    rows = _records(volerr.error_map("MB1", ex / "errors_MB1", grid=4).table())
    for k, a in enumerate("xyz"):
        assert rows[f"max_abs_d{a}"]["value"] == pytest.approx(np.abs(e[:, k]).max(), abs=1e-4)
    length = np.linalg.norm(e, axis=1)
    assert rows["max_length"]["value"] == pytest.approx(length.max(), rel=1e-9)
    assert rows["rms_length"]["value"] == pytest.approx(np.sqrt(np.mean(length ** 2)),
                                                        rel=1e-9)
    assert all(r["unit"] == "um" and r["k"] == 1.0 for r in rows.values())


def test_the_diagonals_table_is_the_first_order_length_change(ex):
    from volerr.tables.functions import ErrorFunctions

    model = volerr.load("MB1")
    funcs = ErrorFunctions.from_dir(ex / "errors_MB1", model)
    res = volerr.diagonals("MB1", ex / "errors_MB1", lines=["space"])
    rows = _records(res.table())
    assert len(rows) == 4
    for line in res.to_dict()["lines"]:
        a, b = np.array(line["start_mm"]), np.array(line["end_mm"])
        q = np.vstack([a, b])
        e = model.volumetric_error(q, funcs(q))
        u = (b - a) / np.linalg.norm(b - a)
        dl_um = float(u @ (e[1] - e[0])) * 1e3
        assert rows[f"dL({line['name']})"]["value"] == pytest.approx(dl_um, abs=1e-6)
        assert rows[f"dL({line['name']})"]["std"] is not None   # the tables carry std


def test_the_iso230_3_table_is_the_drift_files_ranges(ex):
    path = ex / "drift_spindle.csv"
    lines = [ln for ln in path.read_text().splitlines() if not ln.startswith("#")]
    head = lines[0].split(",")
    data = np.array([[float(v) for v in ln.split(",")] for ln in lines[1:]])
    rows = _records(volerr.iso230_3(path).table())
    for col in (c for c in head if c.startswith("d_")):
        d = data[:, head.index(col)]
        drift = d - d[0]                                   # from the first reading, um
        label = col[2:-3]
        assert rows[f"{label}:range"]["value"] == pytest.approx(np.ptp(drift), abs=1e-9)
        assert rows[f"{label}:max"]["value"] == pytest.approx(drift.max(), abs=1e-9)
        assert rows[f"{label}:min"]["value"] == pytest.approx(drift.min(), abs=1e-9)
        assert rows[f"{label}:range"]["unit"] == "um"
