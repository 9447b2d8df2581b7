"""Issue 45 item 2: the test conditions of each standard on the instrument's pages, HTML and
PDF (read back as text): ISO 230-3 (the programme's stages, the sensors' positions from the
drift file's ``# channel`` lines), ISO 10360-2 (positions, lengths, repetitions), the sphere /
R-test set-up of a calibration (its placements) and the ball-plate set-up (plate, its
placements, features, readings), what is not in the data said "not stated".  The expected
texts are read off the input files here, not from volerr's output."""

from __future__ import annotations

import re

import pytest

from volerr.cli import main

pypdf = pytest.importorskip("pypdf")
pytestmark = pytest.mark.xdist_group("conditions_pages")


@pytest.fixture(scope="module")
def ex(tmp_path_factory):
    from volerr.example_files import write_examples

    d = tmp_path_factory.mktemp("conditions")
    write_examples(d)
    return d


def _pages(ex, tmp_path, argv) -> tuple[str, str]:
    """(PDF text with spaces collapsed, HTML) of the command ``argv`` on the examples."""
    out = {k: tmp_path / f"r.{k}" for k in ("html", "pdf")}
    assert main([*argv, "--html", str(out["html"]), "--pdf", str(out["pdf"])]) == 0
    text = "\n".join(p.extract_text() for p in pypdf.PdfReader(str(out["pdf"])).pages)
    return re.sub(r"\s+", " ", text), out["html"].read_text(encoding="utf-8")


def _channel_lines(path) -> dict:
    """``# channel d_x1: X at z=20`` -> {"x1": ("X", "20")} (the file's own header)."""
    out = {}
    for line in path.read_text().splitlines():
        m = re.match(r"# channel d_(\w+): (-?[XYZ])(?: at z=([\d.]+))?", line)
        if m:
            out[m.group(1)] = (m.group(2), m.group(3))
    return out


def test_iso230_3_pages_state_stages_and_sensor_positions(ex, tmp_path, monkeypatch):
    monkeypatch.chdir(ex)
    text, html = _pages(ex, tmp_path, ["iso230-3", "drift_spindle.csv"])
    chans = _channel_lines(ex / "drift_spindle.csv")
    assert len(chans) == 5
    import numpy as np

    rpm = np.loadtxt(ex / "drift_spindle.csv", delimiter=",", skiprows=7, usecols=1)
    n_stages = 1 + int(np.count_nonzero(np.diff(rpm) != 0))   # the example's speeds are exact
    for page in (text, html):
        assert "ISO 230-3 (thermal effects)" in page
        assert f"{n_stages} stages by S_rpm" in page
        for label, (d, z) in chans.items():
            where = f"z {z} mm" if z else "height not given"
            assert f"{label} ({d}, {where})" in page, (label, d, z)
    assert "compensation not stated" in text


def test_iso10360_pages_state_positions_lengths_repetitions(ex, tmp_path, monkeypatch):
    monkeypatch.chdir(ex)
    text, html = _pages(ex, tmp_path, ["iso10360", "MB1", "--errors", "errors_MB1"])
    for page in (text, html):
        assert "ISO 10360-2 (CMM length measurement)" in page
        assert "diagonal +X+Y+Z" in page and "axis Z" in page
    assert "repetitions 3" in text and "compensation not stated" in text


def test_calibration_pages_state_the_sphere_and_plate_set_ups(ex, tmp_path, monkeypatch):
    monkeypatch.chdir(ex)
    text, html = _pages(ex, tmp_path, ["calibrate", "DMU50", "sphere_example_DMU50.csv"])
    rows = (ex / "sphere_example_DMU50.csv").read_text().splitlines()
    n = sum(1 for r in rows if r and not r.startswith("#")) - 1
    for page in (text, html):
        assert "sphere / R-test set-up" in page
    assert f"readings {3 * n}" in text          # three deviations per probed point
    assert "sphere radius not stated" in text
    plate = ex / "ballplate_MB1.csv"
    lines = [r.split(",") for r in plate.read_text().splitlines()[1:] if r]
    placements = sorted({r[0] for r in lines})
    text, html = _pages(ex, tmp_path, ["calibrate", "MB1", "ballplate_MB1.csv"])
    for page in (text, html):
        assert "ball / hole plate set-up" in page
    assert f"placements {len(placements)} ({', '.join(placements)})" in text
    assert f"features {len(lines)} probed in all" in text
    assert "plate calibration not stated" in text
