"""Layout TC_XZ (issue 35 item 6), a two-axis turning centre: Z carriage on the bed, X cross
slide on it carrying the turret, the workpiece on the spindle C.  Its chain against an
independent hand computation: the product of small-angle HTMs written here, without volerr's
derivation or generated code."""

from __future__ import annotations

import numpy as np
import pytest

import volerr


@pytest.fixture(scope="module")
def lathe():
    return volerr.load("TC_XZ")


def small(a=0.0, b=0.0, c=0.0, x=0.0, y=0.0, z=0.0):
    """Small-angle HTM of a rigid error motion (rotations a, b, c rad about x, y, z)."""
    return np.array([[1, -c, b, x], [c, 1, -a, y], [-b, a, 1, z], [0, 0, 0, 1.0]])


def trans(x, y, z):
    m = np.eye(4)
    m[:3, 3] = (x, y, z)
    return m


def rot_z(deg):
    c, s = np.cos(np.radians(deg)), np.sin(np.radians(deg))
    m = np.eye(4)
    m[:2, :2] = [[c, -s], [s, c]]
    return m


def motion(e, axis):
    g = lambda p: e.get(p + axis, 0.0)  # noqa: E731
    return small(g("EA"), g("EB"), g("EC"), g("EX"), g("EY"), g("EZ"))


def tool_in_work(x, z, c_deg, tool, e):
    """The tool point in the workpiece frame: the workpiece turns by -C with the spindle (so the
    base appears turned by +C in it), the spindle's location and motion errors act at the
    workpiece end; on the tool side the Z carriage (its squareness EB0Z tilting its line of
    motion towards +x), then the X slide, then the tool offset."""
    sq_z = trans(e.get("EB0Z", 0.0) * z, 0, 0)
    loc_c = small(e.get("EA0C", 0.0), e.get("EB0C", 0.0), 0.0, e.get("EX0C", 0.0),
                  e.get("EY0C", 0.0), 0.0)
    base2work = rot_z(c_deg) @ loc_c @ motion(e, "C")
    tool2base = trans(0, 0, z) @ sq_z @ motion(e, "Z") @ trans(x, 0, 0) @ motion(e, "X")
    return (base2work @ tool2base @ np.r_[tool, 1.0])[:3]


def test_listed_with_its_axes(lathe):
    assert "TC_XZ" in volerr.layouts()
    assert set(lathe.axes) == {"X", "Z", "C"} and lathe.rotary_axes == ("C",)
    assert "EB0Z" in lathe.parameters
    assert not {"EC0Y", "EA0Z"} & set(lathe.parameters)        # no Y axis
    assert {"EX0C", "EY0C", "EA0C", "EB0C"} <= set(lathe.parameters)


def test_forward_is_the_tool_point_turned_with_the_spindle(lathe):
    rng = np.random.default_rng(5)
    tool = np.array([2.0, -1.0, -30.0])
    for _ in range(8):
        x, z, c = rng.uniform(-50, 250), rng.uniform(0, 600), rng.uniform(-180, 180)
        q = np.array([[{"X": x, "Z": z, "C": c}[a] for a in lathe.axes]])
        got = lathe.forward(q, tool)[0, :3]
        np.testing.assert_allclose(got, tool_in_work(x, z, c, tool, {}), atol=1e-10)


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_volumetric_error_is_the_small_angle_htm_product(lathe, seed):
    """Every parameter at once (1e-4 mm / rad): the first order of the product, its
    symmetric difference (P(e) - P(-e)) / 2, which holds no second-order term."""
    rng = np.random.default_rng(seed)
    e = {p: rng.normal(0, 1e-4) for p in lathe.parameters}
    neg = {p: -v for p, v in e.items()}
    tool = np.array([rng.uniform(-5, 5), rng.uniform(-5, 5), rng.uniform(-60, 0)])
    for _ in range(4):
        x, z, c = rng.uniform(-50, 250), rng.uniform(0, 600), rng.uniform(-180, 180)
        q = np.array([[{"X": x, "Z": z, "C": c}[a] for a in lathe.axes]])
        want = 0.5 * (tool_in_work(x, z, c, tool, e) - tool_in_work(x, z, c, tool, neg))
        got = lathe.volumetric_error(q, e, probe=tool)[0]
        np.testing.assert_allclose(got, want, atol=1e-11)


def test_spindle_growth_reads_on_a_drift_channel(lathe, tmp_path):
    """A drift test on the lathe: a radial sensor along X at C = 0 reads the spindle axis'
    radial offset EX0C one to one, an axial sensor (Z) the carriage's EZZ; the X sensor at two
    heights on a test bar differs by the spindle's tilt EB0C times the height difference."""
    from volerr.instruments import read

    rows = "\n".join(f"{15 * i},{0.1 * i},{0.2 * i},{-0.05 * i * i},{20 + 0.01 * i}"
                     for i in range(30))
    f = tmp_path / "lathe.csv"
    f.write_text("# channel d_r1: X at z=-10\n# channel d_r2: X at z=-110\n# channel d_ax: Z\n"
                 f"t_s,d_r1_um,d_r2_um,d_ax_um,T_head\n{rows}\n", encoding="utf-8")
    obs = read(f, lathe)
    s = obs.sensitivity(lathe)[:, 0, :]
    names = list(lathe.parameters)
    n = 30
    r1, r2, ax = s[0], s[n], s[2 * n]
    assert r1[names.index("EX0C")] == pytest.approx(1.0)
    assert ax[names.index("EZZ")] == pytest.approx(1.0) and ax[names.index("EX0C")] == 0
    # the sensors sit 100 mm apart along z: their difference is 100 mm times the tilt
    assert (r1 - r2)[names.index("EB0C")] == pytest.approx(100.0)
