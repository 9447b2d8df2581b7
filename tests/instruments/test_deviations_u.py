"""Deviations files: the optional ``u_um`` column (issue 43 follow-up).

A deviations file may declare the standard uncertainty of its readings (``u_um``, per
coordinate, k = 1); it weighs the rows and is the ``u`` of the residual rule (chi2 = sum
(r / u)^2).  Without it 1 um is assumed.  The campaign (tests/helpers/instrument_sim.py, the
independent simulator): 160 random points of MB1 with a squareness EC0Y = 20 urad and a scale
EXX@slope = 0.02 um/mm, Gaussian noise of 3 um per coordinate.

* ``u_um = 3`` declared: chi2/dof about 1 (480 readings, 2 parameters and 6 set-up unknowns:
  the 99.9 % band of chi2/dof for ~470 dof is about 0.8 .. 1.2), verdict consistent;
* the same readings without the column: u 1 um assumed, chi2/dof about 3^2 = 9: refused;
* the reader: ``sigma`` = u in mm, not a covariate; u <= 0 refused with one line.
"""

from __future__ import annotations

import numpy as np
import pytest

from helpers import instrument_sim as S
from instruments._common import Campaign

import volerr
from volerr.errors import InputError

pytestmark = pytest.mark.xdist_group("deviations_u")

NOISE_UM = 3.0


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    folder = tmp_path_factory.mktemp("dev_u")
    m = S.Machine("MB1")
    rng = np.random.default_rng(7)
    block = S.deviations_block(m, "dev.csv", 160, rng, u_um=NOISE_UM)
    terms = [S.constant("EC0Y"), S.series("EXX", 1, 0.0, 900.0)]
    camp = Campaign(m, [block], terms, {"EC0Y": 20.0, "EXX@slope": 0.02}, {}, seed=11)
    cols = S.columns(m, block, camp.y[0])
    plain = S.write_csv(folder / "plain.csv", cols)
    declared = S.write_csv(folder / "declared.csv", {**cols, "u_um": np.full(block.n, NOISE_UM)})
    zero = S.write_csv(folder / "zero.csv", {**cols, "u_um": np.zeros(block.n)})
    return {"plain": plain, "declared": declared, "zero": zero}


def _cal(path, **kw):
    return volerr.calibrate("MB1", [path], parameters="EC0Y,EXX@slope", degree=1, plan=False,
                            progress=False, **kw)


def test_the_reader_takes_u_as_the_readings_uncertainty(files):
    from volerr.instruments.deviations import read_deviations

    model = volerr.load("MB1")
    obs = read_deviations(files["declared"], model)
    assert obs.sigma is not None and np.allclose(obs.sigma, NOISE_UM * 1e-3)
    assert "u_um" not in obs.covariates
    assert obs.reference_sigma() == pytest.approx(NOISE_UM * 1e-3)
    assert read_deviations(files["plain"], model).sigma is None


def test_declared_u_makes_the_fit_consistent(files):
    cal = _cal(files["declared"])
    fit = cal.fit
    assert 0.8 < fit["chi2_per_dof"] < 1.2, fit
    assert fit["verdict"] == "consistent"
    assert "median 3 um" in fit["u"]
    # the planted values within 4 standard uncertainties
    for name, true in (("EC0Y", 20.0), ("EXX@slope", 0.02)):
        v = cal.parameters[name]
        assert abs(v["value"] - true) < 4 * v["std"], (name, v)


def test_without_u_the_default_1_um_refuses_it(files):
    with pytest.raises(InputError) as e:
        _cal(files["plain"])
    msg = str(e.value)
    assert "chi2/dof" in msg and "\n" not in msg
    ratio = float(msg.split("chi2/dof = ")[1].split(",")[0])
    assert 7.0 < ratio < 11.5, msg           # (3 um / 1 um)^2 = 9


def test_a_non_positive_u_is_refused(files):
    from volerr.instruments.deviations import read_deviations

    with pytest.raises(InputError) as e:
        read_deviations(files["zero"], volerr.load("MB1"))
    assert "u_um" in str(e.value) and "positive" in str(e.value)
    assert "zero.csv" in str(e.value)
