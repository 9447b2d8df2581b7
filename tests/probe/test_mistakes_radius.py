"""``volerr probe-cal`` with a sphere or ball radius that the probe points cannot explain:
refused (exit 2, one line naming the likely mistake, nothing written).

The ball centres are built here: a hemisphere of directions around a centre, at the distance
sphere radius + stylus-ball radius (no volerr code), with a small pretravel pattern.
"""

import numpy as np
import pytest

from volerr.cli import main

C0 = np.array([250.0, 180.0, -40.0])


def _centres(sphere_radius, ball_radius, pretravel_um=3.0):
    """Stylus-ball centres of a probing of the upper hemisphere, mm."""
    pts = [(0.0, 0.0)]
    for phi in (18, 36, 54, 72, 90):
        pts += [(phi, th) for th in range(0, 360, 30)]
    out = []
    for phi, th in pts:
        p, t = np.radians(phi), np.radians(th)
        n = np.array([np.sin(p) * np.cos(t), np.sin(p) * np.sin(t), np.cos(p)])
        r = sphere_radius + ball_radius - pretravel_um * 1e-3 * (1 + 0.3 * np.cos(3 * t))
        out.append(C0 + r * n)
    return np.array(out)


def _run(tmp_path, capsys, pts, radius, extra=()):
    f = tmp_path / "sphere.csv"
    f.write_text("x,y,z\n" + "\n".join(",".join(f"{v:.7f}" for v in p) for p in pts) + "\n")
    out, js = tmp_path / "map.csv", tmp_path / "s.json"
    code = main(["probe-cal", str(f), "--sphere-radius", str(radius), "--out", str(out),
                 "--json", str(js), *extra])
    err = capsys.readouterr().err
    return code, err, (out, js)


def _refused(tmp_path, capsys, pts, radius, *needles, extra=()):
    code, err, outs = _run(tmp_path, capsys, pts, radius, extra)
    assert code == 2, err
    assert err.count("\n") == 1 and "Traceback" not in err, err
    assert "--sphere-radius" in err
    for n in needles:
        assert n in err, (n, err)
    assert not any(p.exists() for p in outs)


def test_the_diameter_given_for_the_radius(tmp_path, capsys):
    """The issue's case: a 10 mm (radius) sphere, --sphere-radius 20."""
    _refused(tmp_path, capsys, _centres(10.0, 1.5), 20,
             "the diameter given for the radius", "10 mm would fit")


def test_the_radius_in_inches(tmp_path, capsys):
    """A 1 inch sphere (radius 12.7 mm) given as 0.5: a 12.7 mm 'ball' is no stylus."""
    _refused(tmp_path, capsys, _centres(12.7, 1.0), 0.5, "inches", "12.7 mm would fit")


def test_contact_points_instead_of_ball_centres(tmp_path, capsys):
    """Probe-corrected contact points lie on the sphere itself: no ball radius left."""
    _refused(tmp_path, capsys, _centres(25.0, 0.0, pretravel_um=-2.0), 25.0, "contact points")


def test_another_sphere_with_the_ball_radius_given(tmp_path, capsys):
    """20 given for the 25 mm sphere: a 6 mm ball is possible, but not the declared 1 mm
    ball (more than any pretravel)."""
    _refused(tmp_path, capsys, _centres(25.0, 1.0), 20, "another sphere's radius",
             "24.99", extra=("--ball-radius", "1"))


def test_the_ball_diameter_given_as_its_radius(tmp_path, capsys):
    _refused(tmp_path, capsys, _centres(25.0, 1.0), 25.0, "ball's diameter",
             extra=("--ball-radius", "2"))


def test_consistent_radii_pass(tmp_path, capsys):
    """The right sphere and ball radius: R_eff = ball radius - mean pretravel."""
    code, err, (out, js) = _run(tmp_path, capsys, _centres(25.0, 1.0), 25.0,
                                ("--ball-radius", "1"))
    assert code == 0, err
    import json

    r_eff = json.loads(js.read_text())["r_eff_mm"]
    assert r_eff == pytest.approx(1.0 - 3e-3, abs=1e-3)
