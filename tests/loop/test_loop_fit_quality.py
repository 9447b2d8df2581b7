"""Issue 43 item 3 on ``volerr loop`` (3-D deviations): the augmented fit judged by its residual
against the readings' declared uncertainty (:mod:`volerr.fit_quality`; a deviations file
declares none: 1 um per coordinate is assumed, and the JSON says so).

MB1, 120 random points, squareness planted, Gaussian noise 1 um per coordinate, from the
independent simulator (tests/helpers/instrument_sim.py): chi2/dof about 1, written.  The same
file with its deviations times 3 (a unit mistake: still a few um, nothing a reader refuses) has
noise 3 um against 1 um, chi2/dof about 9: exit 2, one line, no JSON, no error directory; with
``--accept-residual`` written, the JSON, the console, the HTML and the error tables marked.
"""

import csv
import json

import numpy as np
import pytest

from helpers import instrument_sim as S
from instruments._common import Campaign
from volerr.cli import main

pytestmark = pytest.mark.xdist_group("loop_fit_quality")


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    folder = tmp_path_factory.mktemp("loop_fitq")
    m = S.Machine("MB1")
    dev = S.deviations_block(m, "dev.csv", 120, np.random.default_rng(3),
                             probes=((0, 0, 0), (0, 0, 100.0)), u_um=1.0)
    camp = Campaign(m, [dev], [S.constant(c) for c in ("EC0Y", "EB0Z", "EA0Z")],
                    {"EC0Y": 20.0, "EB0Z": -15.0, "EA0Z": 10.0}, {}, seed=4)
    clean = camp.write(folder)[0]
    with open(clean, newline="") as fh:
        rows = list(csv.reader(fh))
    cols = [rows[0].index(c) for c in ("dx_um", "dy_um", "dz_um")]
    for r in rows[1:]:
        for k in cols:
            r[k] = repr(3.0 * float(r[k]))
    x3 = folder / "dev_x3.csv"
    with open(x3, "w", newline="") as fh:
        csv.writer(fh).writerows(rows)
    return clean, str(x3)


def test_clean_deviations_are_consistent(files, tmp_path):
    clean, _ = files
    out = tmp_path / "l.json"
    assert main(["loop", "MB1", clean, "--json", str(out)]) == 0
    fit = json.loads(out.read_text())["fit"]
    assert set(fit) >= {"chi2_per_dof", "dof", "p_value", "verdict"}
    assert "1 um" in fit["u"]
    assert abs(fit["chi2_per_dof"] - 1.0) < 5 * np.sqrt(2.0 / fit["dof"]), fit


def test_deviations_times_3_are_refused(files, tmp_path, capsys):
    _, x3 = files
    js, page, errs = tmp_path / "l.json", tmp_path / "l.html", tmp_path / "errs"
    argv = ["loop", "MB1", x3, "--json", str(js), "--html", str(page), "--errors-out",
            str(errs)]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "chi2/dof" in err and "Traceback" not in err, err
    ratio = float(err.split("chi2/dof = ")[1].split(",")[0])
    assert 6.0 < ratio < 13.0, err
    assert not js.exists() and not page.exists() and not errs.exists()
    assert main(argv + ["--accept-residual"]) == 0
    assert "FORCED" in capsys.readouterr().out
    doc = json.loads(js.read_text())
    assert doc["fit"]["verdict"] == "forced" and "FORCED" in doc["forced"]
    assert "FORCED" in page.read_text()
    for table in errs.iterdir():
        assert "FORCED" in table.read_text().splitlines()[0], table.name


def test_the_api_refuses_or_returns_it_marked(files, tmp_path):
    """volerr.loop applies the residual rule itself, before anything is written (out_dir
    stays empty); with accept_residual=True the result comes back marked forced."""
    import volerr
    from volerr.errors import InputError

    _, x3 = files
    out = tmp_path / "aug"
    with pytest.raises(InputError) as e:
        volerr.loop("MB1", x3, out_dir=out, families="step", progress=False)
    assert "chi2/dof" in str(e.value) and "dev_x3.csv" in str(e.value)
    assert not out.exists() or not any(out.iterdir())
    rep = volerr.loop("MB1", x3, families="step", progress=False, accept_residual=True)
    assert rep.fit["verdict"] == "forced" and "FORCED" in rep.data["forced"]
    assert "FORCED" in rep.summary()
