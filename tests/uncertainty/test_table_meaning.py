"""One meaning of the tables' uncertainty columns (issue 23): ``_std`` = standard uncertainty
of the tabulated value, ``_s`` = repeatability of one reading.  From ``identify`` tables of n
rounds, the Monte Carlo uncertainty of a distance that depends on EXX alone equals the GUM
result for the mean of n rounds, computed here from the rounds identified one at a time."""

from __future__ import annotations

import csv
import json

import numpy as np
import pytest

from volerr.cli import main
from volerr.identify.tracker_io import example_path

#: the two probing points of the task, on a line along X through nodes of the table (mm)
X1, X2 = 100.0, 400.0


def _identify(files, out_dir):
    assert main(["identify", "MB1", "--axis", "X", *map(str, files),
                 "--errors-out", str(out_dir)]) == 0
    with open(out_dir / "X.csv", newline="") as fh:
        return list(csv.DictReader(fh))


@pytest.fixture(scope="module")
def tables(tmp_path_factory):
    """The identify table of all rounds, and EXX of every round identified on its own."""
    d = tmp_path_factory.mktemp("meaning")
    lines = example_path("X").read_text().splitlines()
    head = [ln for ln in lines if ln.startswith(("#", "round"))]
    rounds = sorted({ln.split(",")[0] for ln in lines if ln[:1].isdigit()})
    per_round = []
    for r in rounds:
        f = d / f"round{r}.csv"
        f.write_text("\n".join(head + [ln for ln in lines if ln.split(",")[0] == r]) + "\n")
        rows = _identify([f], d / f"only{r}")
        per_round.append({float(row["X"]): float(row["EXX_um"]) for row in rows})
    rows = _identify([example_path("X")], d / "all")
    return d, rows, per_round


def _exx_only(rows, path):
    """An error directory with EXX and its uncertainty columns only."""
    path.mkdir()
    keep = ["X", "EXX_um", "EXX_std_um", "EXX_s_um"]
    text = ",".join(keep) + "\n" + "".join(",".join(r[k] for k in keep) + "\n" for r in rows)
    (path / "X.csv").write_text(text)
    return path


def _u_distance(capsys, tmp_path, errors, *extra) -> dict:
    task = tmp_path / "task.csv"
    task.write_text(f"X,Y,Z\n{X1},300,200\n{X2},300,200\n")
    out = tmp_path / "u.json"
    assert main(["uncertainty", "MB1", "--task", str(task), "--evaluate", "distance",
                 "--errors", str(errors), "--samples", "20000", "--seed", "3",
                 "--contributions", "0", "--quiet", "--json", str(out), *extra]) == 0
    capsys.readouterr()
    return json.loads(out.read_text())


def test_identify_writes_s_and_s_over_sqrt_n(tables):
    _, rows, per_round = tables
    n = len(per_round)
    assert n == 4
    for row in rows:
        x = float(row["X"])
        vals = np.array([r[x] for r in per_round])
        s = vals.std(ddof=1)
        assert float(row["EXX_um"]) == pytest.approx(vals.mean(), abs=1e-6)
        assert float(row["EXX_s_um"]) == pytest.approx(s, abs=1e-6)
        assert float(row["EXX_std_um"]) == pytest.approx(s / np.sqrt(n), abs=1e-6)


def test_uncertainty_from_identify_tables_is_the_gum_result_for_the_mean(tables, tmp_path,
                                                                           capsys):
    d, rows, per_round = tables
    n = len(per_round)
    # GUM for the mean of n rounds: d_meas = L - (EXX(x2) - EXX(x1)); the two node means are
    # independent, each with u^2 = s^2 / n (s: standard deviation of the rounds' values)
    s1 = np.std([r[X1] for r in per_round], ddof=1)
    s2 = np.std([r[X2] for r in per_round], ddof=1)
    u_gum = np.sqrt((s1 ** 2 + s2 ** 2) / n)
    errors = _exx_only(rows, tmp_path / "e")
    doc = _u_distance(capsys, tmp_path, errors)
    q = doc["quantities"]["distance"]
    # Monte Carlo standard deviation of u from 20000 samples: 0.5 %; 3 % is 6 of those
    assert q["standard_uncertainty_um"] == pytest.approx(u_gum, rel=0.03)
    # the report says which column was used, and how
    used = {t["column"]: t for t in doc["table_uncertainty"]}
    assert "tabulated value" in used["EXX_std"]["meaning"]
    assert "per simulated machine" in used["EXX_std"]["drawn"]
    assert used["EXX_s"]["drawn"].startswith("not used")
    # with --repeatability the single-reading scatter is drawn at each of the two points too
    doc = _u_distance(capsys, tmp_path, errors, "--repeatability")
    u_rep = np.sqrt((s1 ** 2 + s2 ** 2) * (1 + 1 / n))
    assert doc["quantities"]["distance"]["standard_uncertainty_um"] == pytest.approx(u_rep,
                                                                                    rel=0.03)
    assert "EXX repeatability" in doc["sources"]


def test_old_tables_keep_their_reading(tables, tmp_path, capsys):
    """--table-std repeatability: an old table whose _std held a single-reading scatter is
    drawn per point (here the two readings at different nodes: the same u as per node)."""
    _, rows, per_round = tables
    old = tmp_path / "old"
    old.mkdir()
    text = "X,EXX_um,EXX_std_um\n" + "".join(f"{r['X']},{r['EXX_um']},{r['EXX_s_um']}\n"
                                            for r in rows)
    (old / "X.csv").write_text(text)
    s1 = np.std([r[X1] for r in per_round], ddof=1)
    s2 = np.std([r[X2] for r in per_round], ddof=1)
    doc = _u_distance(capsys, tmp_path, old, "--table-std", "repeatability")
    assert doc["quantities"]["distance"]["standard_uncertainty_um"] == pytest.approx(
        np.hypot(s1, s2), rel=0.03)
    assert "repeatability" in doc["table_uncertainty"][0]["meaning"]


def test_result_statement_corrected_and_uncorrected():
    """--bias: the corrected result is the reading minus the bias with the reading's interval
    shifted by -bias; the uncorrected one is the reading with the smallest interval that holds
    both the reading's interval and the corrected one (so the bias is inside it)."""
    from hypothesis import given, settings, strategies as st

    from volerr.uncertainty.report import statement

    @settings(max_examples=60, deadline=None)
    @given(st.floats(-50, 50), st.floats(0.01, 5), st.floats(-1, 1))
    def check(bias_um, half_um, skew):
        est = 400.0
        lo = est - half_um * 1e-3 * (1 + 0.2 * skew)
        hi = est + half_um * 1e-3
        q = {"estimate_mm": est, "bias_um": bias_um, "coverage_interval_mm": [lo, hi]}
        c, u = statement(q, "corrected"), statement(q, "uncorrected")
        b = bias_um * 1e-3
        assert c["result_mm"] == pytest.approx(est - b)
        assert c["result_interval_mm"] == pytest.approx([lo - b, hi - b])
        assert u["result_mm"] == est
        ulo, uhi = u["result_interval_mm"]
        assert ulo <= min(lo, lo - b) + 1e-12 and uhi >= max(hi, hi - b) - 1e-12
        assert ulo == pytest.approx(min(lo, lo - b)) and uhi == pytest.approx(max(hi, hi - b))
        assert u["result_U_minus_um"] == pytest.approx((est - ulo) * 1e3)
        assert u["result_U_plus_um"] == pytest.approx((uhi - est) * 1e3)

    check()
