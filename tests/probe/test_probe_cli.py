"""``volerr probe-cal``: outputs per INTERFACE.md, plan generation, bad input (exit 2)."""

from __future__ import annotations

import csv
import json
import math

import numpy as np
import pytest

from volerr.probe import calibration as probe
from volerr.probe import plans as pp
from volerr.cli import main

R_S, R_BALL = 25.006, 1.006
C0 = np.array([250.0, 180.0, -40.0])


def write_points(path, pts, angles=None):
    lines = ["x,y,z" + (",phi_deg,theta_deg" if angles is not None else "")]
    for i, p in enumerate(pts):
        row = ",".join(f"{v:.7f}" for v in p)
        if angles is not None:
            row += f",{angles[0][i]:.4f},{angles[1][i]:.4f}"
        lines.append(row)
    path.write_text("\n".join(lines) + "\n")
    return path


@pytest.fixture()
def data(tmp_path):
    pts = pp.simulate_probing(pp.pahk_plan(), C0, R_S, R_BALL, noise_mm=0.3e-3, rng=11)
    return write_points(tmp_path / "sphere.csv", pts), pts


def read_map(path):
    with open(path, newline="") as fh:
        return list(csv.DictReader(fh))


def test_calibration_outputs(tmp_path, data, capsys):
    path, pts = data
    out, js = tmp_path / "map.csv", tmp_path / "cal.json"
    assert main(["probe-cal", str(path), "--sphere-radius", str(R_S), "--out", str(out),
                 "--json", str(js)]) == 0
    rows = read_map(out)
    assert list(rows[0])[:3] == ["phi_deg", "theta_deg", "probe_um"]
    assert len(rows) == len(pts)
    s = json.loads(js.read_text())
    # independent: sphere centre and eq. (13) from the printed centre and R_eff
    r_m = np.linalg.norm(pts - np.array(s["center_mm"]), axis=1)
    probe_um = (s["r_eff_mm"] - (r_m - R_S)) * 1e3
    np.testing.assert_allclose([float(r["probe_um"]) for r in rows], probe_um, atol=2e-3)
    assert s["probe_error_um"]["max"] == pytest.approx(probe_um.max(), abs=2e-3)
    assert s["probe_error_um"]["min"] == pytest.approx(probe_um.min(), abs=2e-3)
    assert s["probe_error_um"]["rms"] == pytest.approx(math.sqrt(np.mean(probe_um ** 2)),
                                                       abs=2e-3)
    assert s["r_eff_mm"] == pytest.approx(0.997, abs=1e-3)
    # directions from the fitted centre, probe frame = machine frame (A = B = 0)
    u = pts - np.array(s["center_mm"])
    phi = np.degrees(np.arccos(u[:, 2] / np.linalg.norm(u, axis=1)))
    np.testing.assert_allclose([float(r["phi_deg"]) for r in rows], phi, atol=1e-5)
    assert "R_eff" in capsys.readouterr().out


def test_given_directions_are_echoed(tmp_path):
    plan = pp.pahk_plan()
    pts = pp.simulate_probing(plan, C0, R_S, R_BALL, noise_mm=0.2e-3, tilt_deg=60,
                              roll_deg=30, rng=1)
    path = write_points(tmp_path / "s.csv", pts, (plan.phi_deg, plan.theta_deg))
    out = tmp_path / "m.csv"
    assert main(["probe-cal", str(path), "--sphere-radius", str(R_S), "--out", str(out),
                 "--tilt-deg", "60", "--roll-deg", "30"]) == 0
    rows = read_map(out)
    np.testing.assert_allclose([float(r["phi_deg"]) for r in rows], plan.phi_deg, atol=1e-4)
    np.testing.assert_allclose([float(r["theta_deg"]) for r in rows], plan.theta_deg,
                               atol=1e-4)


def test_plan_round_trip(tmp_path, capsys):
    plan_csv, out = tmp_path / "plan.csv", tmp_path / "map.csv"
    assert main(["probe-cal", "--plan", str(plan_csv), "--sphere-radius", str(R_S),
                 "--ball-radius", "1.0", "--center", "1,2,3"]) == 0
    d = probe.read_sphere_csv(plan_csv)
    assert len(d.points) == 101
    np.testing.assert_allclose(np.linalg.norm(d.points - [1, 2, 3], axis=1), R_S + 1.0,
                               atol=1e-6)
    # a perfect probe on the nominal plan: R_eff = ball radius, no probe error
    assert main(["probe-cal", str(plan_csv), "--sphere-radius", str(R_S), "--out",
                 str(out)]) == 0
    vals = [float(r["probe_um"]) for r in read_map(out)]
    assert max(abs(v) for v in vals) < 1e-2
    assert main(["probe-cal", "--plan", str(tmp_path / "c.csv"), "--sphere-radius", "10",
                 "--ball-radius", "2", "--phis", "30,60,90", "--per-circle", "8",
                 "--no-pole"]) == 0
    assert len(probe.read_sphere_csv(tmp_path / "c.csv").points) == 24


def test_plots(tmp_path, data):
    path, _ = data
    assert main(["probe-cal", str(path), "--sphere-radius", str(R_S), "--out",
                 str(tmp_path / "m.csv"), "--plots", str(tmp_path / "fig"),
                 "--plot", str(tmp_path / "both.png")]) == 0
    for f in (tmp_path / "fig" / "probe_map_3d.png", tmp_path / "fig" / "probe_map_2d.png",
              tmp_path / "both.png"):
        assert f.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def bad_cases(tmp_path, pts):
    def w(name, text):
        p = tmp_path / name
        p.write_text(text)
        return p

    rows = "\n".join(",".join(f"{v:.6f}" for v in p) for p in pts)
    circle = pp.simulate_probing(pp.circles_plan([54], 20, pole=False), C0, R_S, R_BALL)
    return {
        "missing column": (w("a.csv", "x,y\n1,2\n"), R_S, "missing column 'z'"),
        "nan": (w("b.csv", "x,y,z\n" + rows.replace(rows.split("\n")[4], "1,nan,3")),
                R_S, "NaN"),
        "text": (w("c.csv", "x,y,z\n" + rows.replace(rows.split("\n")[2], "1,abc,3")),
                 R_S, "not a number"),
        "few points": (w("d.csv", "x,y,z\n" + "\n".join(rows.split("\n")[:5])), R_S,
                       "at least"),
        "circle": (w("e.csv", "x,y,z\n" + "\n".join(",".join(f"{v:.6f}" for v in p)
                                                    for p in circle)), R_S, "one plane"),
        "diameter": (w("f.csv", "x,y,z\n" + rows), 2 * R_S, "not a diameter"),
        "absurd": (w("g.csv", "x,y,z\n" + rows), 0.4, "plausible"),
        "negative": (w("h.csv", "x,y,z\n" + rows), -25.0, "positive"),
        "empty": (w("i.csv", ""), R_S, "empty"),
        "no rows": (w("j.csv", "x,y,z\n"), R_S, "no data"),
        "phi only": (w("k.csv", "x,y,z,phi_deg\n1,2,3,4\n"), R_S, "both"),
        "duplicate column": (w("l.csv", "x,y,z,X\n" + "\n".join(r + ",0" for r in rows.split("\n"))),
                             R_S, "twice"),
        "missing file": (tmp_path / "nope.csv", R_S, "no such file"),
    }


@pytest.mark.parametrize("case", ["missing column", "nan", "text", "few points", "circle",
                                  "diameter", "absurd", "negative", "empty", "no rows",
                                  "phi only", "missing file", "duplicate column"])
def test_bad_input_exit_2(tmp_path, case, capsys):
    pts = pp.simulate_probing(pp.pahk_plan(), C0, R_S, R_BALL, noise_mm=0.2e-3, rng=0)
    path, radius, message = bad_cases(tmp_path, pts)[case]
    before = path.read_bytes() if path.exists() else None
    out = tmp_path / "out.csv"
    code = main(["probe-cal", str(path), "--sphere-radius", str(radius), "--out", str(out)])
    err = capsys.readouterr().err
    assert code == 2
    assert err.count("\n") == 1 and err.startswith("volerr probe-cal: error:"), err
    assert message in err
    assert "Traceback" not in err
    assert not out.exists()
    if before is not None:
        assert path.read_bytes() == before


def test_refuses_to_overwrite_input(data, capsys):
    path, _ = data
    before = path.read_bytes()
    assert main(["probe-cal", str(path), "--sphere-radius", str(R_S), "--out",
                 str(path)]) == 2
    assert "refusing to overwrite" in capsys.readouterr().err
    assert path.read_bytes() == before


def test_output_that_is_a_folder_or_under_a_file(tmp_path, data, capsys):
    """--out naming an existing folder, or a path below a file: exit 2, one line, nothing written."""
    path, _ = data
    before = path.read_bytes()
    cases = ((["--out", str(tmp_path)], "is a folder"),
             (["--out", str(path / "m.csv")], "is a file"),
             (["--out", str(tmp_path / "ok.csv"), "--json", str(tmp_path)], "is a folder"))
    for extra, msg in cases:
        code = main(["probe-cal", str(path), "--sphere-radius", str(R_S), *extra])
        err = capsys.readouterr().err
        assert code == 2 and msg in err and err.count("\n") == 1, (extra, err)
        assert "Traceback" not in err
    assert not (tmp_path / "ok.csv").exists()
    assert path.read_bytes() == before
    for extra, msg in ((["--plot", str(tmp_path / "p.txt")], ".png"),
                       (["--plots", str(path)], "not a folder")):
        code = main(["probe-cal", str(path), "--sphere-radius", str(R_S), "--out",
                     str(tmp_path / "ok.csv"), "--json", str(tmp_path / "ok.json"), *extra])
        err = capsys.readouterr().err
        assert code == 2 and msg in err and err.count("\n") == 1, (extra, err)
        assert not (tmp_path / "ok.csv").exists() and not (tmp_path / "ok.json").exists()
    assert path.read_bytes() == before


def test_usage_errors(tmp_path, data, capsys):
    path, _ = data
    assert main(["probe-cal", str(path), "--sphere-radius", str(R_S)]) == 2      # no --out
    assert main(["probe-cal", "--plan", str(tmp_path / "p.csv"),
                 "--sphere-radius", str(R_S)]) == 2                             # no ball
    assert main(["probe-cal", str(path), "--sphere-radius", "abc", "--out", "x"]) == 2
    capsys.readouterr()
    for extra, msg in ((["--degree", "30"], "--degree"), (["--degree", "10"], "coefficients"),
                       (["--outlier-k", "-1"], "outlier"),
                       (["--json", str(tmp_path / "m.csv")], "overwrite")):
        code = main(["probe-cal", str(path), "--sphere-radius", str(R_S), "--out",
                     str(tmp_path / "m.csv"), *extra])
        err = capsys.readouterr().err
        assert code == 2 and msg in err and err.count("\n") == 1, (extra, err)
    assert main(["probe-cal", "--help"]) == 0
    assert "Master-sphere" in capsys.readouterr().out


def test_subprocess_entry_point(tmp_path, data):
    import subprocess
    import sys

    path, _ = data
    r = subprocess.run([sys.executable, "-m", "volerr", "probe-cal", str(path),
                        "--sphere-radius", "50.012", "--out", str(tmp_path / "m.csv")],
                       capture_output=True, text=True)
    assert r.returncode == 2
    assert r.stderr.count("\n") == 1 and "diameter" in r.stderr


def test_demo_sphere_hook(tmp_path):
    from volerr.probe.plans import simulate_demo_sphere

    info = simulate_demo_sphere(tmp_path / "demo.csv")
    out, js = tmp_path / "m.csv", tmp_path / "c.json"
    assert main(["probe-cal", info["path"], "--sphere-radius", str(info["sphere_radius_mm"]),
                 "--out", str(out), "--json", str(js)]) == 0
    s = json.loads(js.read_text())
    np.testing.assert_allclose(s["center_mm"], info["center_mm"], atol=0.02)
    assert 0.99 < s["r_eff_mm"] < info["ball_radius_mm"]
