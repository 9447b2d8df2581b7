"""Audit of Pahk sec. 3 (eq. 11-17): printed forms against the probe-frame derivation."""

from __future__ import annotations

import tomllib
from importlib import resources

import numpy as np
import pytest

from volerr.probe import calibration as probe

#: the module's verdicts come from the full audit (conftest.provider_verdicts), in its group
pytestmark = pytest.mark.xdist_group("full_audit")


@pytest.fixture(scope="module")
def verdicts(provider_verdicts):
    from volerr.derive.audit import probe as audit_probe

    text = (resources.files("volerr.derive.audit") / "data" / audit_probe.DATA_FILE).read_text()
    return {(v.equation, v.component): v
            for v in provider_verdicts(audit_probe, tomllib.loads(text))}


def test_verdicts(verdicts):
    differs = {k for k, v in verdicts.items() if v.verdict == "differs"}
    assert differs == {("12", "Tp"), ("16", "theta")}
    assert "transposed" in verdicts[("12", "Tp")].erratum
    assert "cos B = 0" in verdicts[("12", "Tp")].evidence      # the stray text is quoted
    assert "quadrant" in verdicts[("16", "theta")].erratum
    for key in [("11", "e'_x"), ("11", "e'_y"), ("14", "M'"), ("15", "phi"), ("13", "Probe"),
                ("17", "dXc")]:
        assert verdicts[key].verdict == "identical" and verdicts[key].erratum == ""


def test_erratum_evidence_numerically():
    """The printed Tp maps probe to machine coordinates: its columns are the probe axes."""
    a, b = np.radians(35.0), np.radians(-70.0)
    printed = np.array([[np.cos(a) * np.cos(b), -np.sin(b), -np.sin(a) * np.cos(b)],
                        [np.cos(a) * np.sin(b), np.cos(b), -np.sin(a) * np.sin(b)],
                        [np.sin(a), 0.0, np.cos(a)]])
    np.testing.assert_allclose(printed, probe.probe2machine(35.0, -70.0), atol=1e-15)
    stylus = printed @ [0, 0, 1.0]          # the probe axis z' in machine coordinates
    np.testing.assert_allclose(stylus, [-np.sin(a) * np.cos(b), -np.sin(a) * np.sin(b),
                                        np.cos(a)], atol=1e-15)
    # the stated [x'] = Tp [x] with the printed matrix would not give z' = (0, 0, 1)
    assert not np.allclose(printed @ stylus, [0, 0, 1])


def test_provider_registered():
    from volerr.derive import audit

    assert "volerr.derive.audit.probe" in audit.PROVIDERS


def test_atan2_reading_supported_by_the_full_azimuth_calibration(verdicts):
    """Review 3 (#15): the calibration's 100 points on 5 latitude circles at 18 deg steps
    (seed text, quoted) are 20 azimuths per circle = 360 deg, a range only atan2 covers; a
    one-argument arctangent returns 180 deg of it (checked here on those azimuths)."""
    az = np.radians(np.arange(0, 100 // 5) * 18.0)
    assert np.degrees(az[-1] - az[0]) + 18 == 360
    one = {round(float(x) % 180, 6) % 180 for x in np.degrees(np.arctan(np.tan(az)))}
    two = np.unique(np.round(np.degrees(np.arctan2(np.sin(az), np.cos(az))) % 360, 6))
    assert len(two) == 20 and len(one) == 10
    v = verdicts[("16", "theta")]
    assert v.category == "convention"
    assert "100 on 5 latitude circles" in v.evidence and "= 360 deg" in v.evidence
