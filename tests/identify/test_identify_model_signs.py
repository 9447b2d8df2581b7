"""Identification of a table axis feeds the model: tracker data of points on a moving table
(exact rigid-body simulation of the table's own motion) -> ``identify --signs model`` -> the
model's volumetric error equals the exact error of the tool point relative to the table."""


import numpy as np
import pytest
from helpers.tracker_sim import error_rotation, simulate, smooth_errors, to_csv

import volerr  # noqa: E402
from volerr.cli import main  # noqa: E402
from volerr.tables.functions import ErrorFunctions  # noqa: E402
from volerr.tables.table import read_error_table  # noqa: E402

REF = np.array([[150.0, 40.0, 10.0], [-60.0, 120.0, 30.0], [20.0, -90.0, 5.0]])


@pytest.mark.parametrize("layout,axis,seed", [("FB2", "X", 1), ("FB1", "Y", 2), ("CX", "X", 3)])
def test_table_axis_identified_in_model_signs_reproduces_relative_error(tmp_path, layout,
                                                                        axis, seed):
    model = volerr.load(layout)
    u = np.asarray(model.layout.axes[axis].direction)
    pos = np.linspace(0, 400, 9)
    body = smooth_errors(pos, scale_mm=0.02, scale_rad=80e-6, seed=seed)
    # the table moves its points along -u for +q (tool moves +u relative to the workpiece)
    pts = simulate("linear", REF, pos, body, direction=-u)
    f = tmp_path / "tracker.csv"
    f.write_text(to_csv([pts], pos, ("P", "Q", "K")))
    assert main(["identify", layout, "--axis", axis, str(f), "--signs", "model",
                 "--out", str(tmp_path / f"{axis}.csv")]) == 0
    table = read_error_table(tmp_path / f"{axis}.csv")
    funcs = ErrorFunctions({axis: table}, {}, model, method="linear")
    for probe in ([0.0, 0.0, 0.0], [35.0, -80.0, -120.0]):
        P = np.asarray(probe)
        for k, q in enumerate(pos):
            t, R = body[k, :3], error_rotation(*body[k, 3:])
            # tool point P (fixed in space) in table coordinates: x = -q u + t + R r
            exact = R.T @ (P + q * u - t) - (P + q * u)
            at = {a: np.array([0.0]) for a in model.axes}
            at[axis] = np.array([q])
            got = model.volumetric_error(at, funcs(at), probe=P)[0]
            # first-order model vs exact rigid body: second-order gap |e|^2 |lever| < 1e-5 mm
            np.testing.assert_allclose(got, exact, atol=1e-5)
    # the re-referencing matters: plain negation of the table's motions is far off
    naive = -body[:, :3]
    lever = np.array([model.volumetric_error({**{a: [0.0] for a in model.axes}, axis: [q]},
                                             funcs({**{a: np.array([0.0]) for a in model.axes},
                                                    axis: np.array([q])}))[0] for q in pos])
    assert np.abs(lever - naive).max() > 1e-3


def test_component_signs_are_the_default_and_differ_for_a_table(tmp_path):
    pos = np.linspace(0, 300, 7)
    body = smooth_errors(pos, seed=4)
    pts = simulate("linear", REF, pos, body, direction=(-1, 0, 0))
    f = tmp_path / "t.csv"
    f.write_text(to_csv([pts], pos, ("P", "Q", "K")))
    for signs in ("component", "model"):
        assert main(["identify", "FB2", "--axis", "X", str(f), "--signs", signs,
                     "--out", str(tmp_path / f"{signs}.csv")]) == 0
    comp = read_error_table(tmp_path / "component.csv")
    np.testing.assert_allclose(comp.values["EAX"], body[:, 3], atol=1e-8)
    mod = read_error_table(tmp_path / "model.csv")
    np.testing.assert_allclose(mod.values["EAX"], -body[:, 3], atol=1e-8)


@pytest.mark.parametrize("q0,q1", [(-250.0, 250.0), (250.0, -250.0), (0.0, 250.0)])
def test_tool_axis_measured_from_a_nonzero_reference(tmp_path, q0, q1):
    """DMU50 X (tool side) measured from q0 (frame = machine frame): the tracker's pivot is the
    carriage point at the origin at q0, the model's the one there at q = 0; --signs model
    re-references (t + q0 e x u) and the model reproduces the exact error of the tool tip."""
    model = volerr.load("DMU50")
    u = np.array([1.0, 0.0, 0.0])
    pos = np.linspace(q0, q1, 11)
    body = smooth_errors(pos, scale_mm=0.02, scale_rad=80e-6, seed=9)
    pts = simulate("linear", REF, pos, body, direction=u)
    f = tmp_path / "tracker.csv"
    f.write_text(to_csv([pts], pos, ("P", "Q", "K")))
    assert main(["identify", "DMU50", "--axis", "X", str(f), "--signs", "model",
                 "--out", str(tmp_path / "X.csv")]) == 0
    table = read_error_table(tmp_path / "X.csv")
    funcs = ErrorFunctions({"X": table}, {}, model, method="linear")
    for y, z in ((0.0, 0.0), (50.0, 200.0)):
        for k, q in enumerate(pos):
            t, R = body[k, :3], error_rotation(*body[k, 3:])
            tip = np.array([q, y, z])
            carriage = (q - q0) * u            # the body point at the origin at q0
            exact = carriage + t + R @ (tip - carriage) - tip
            at = {"X": np.array([q]), "Y": np.array([y]), "Z": np.array([z]),
                  "B": np.array([0.0]), "C": np.array([0.0])}
            got = model.volumetric_error(at, funcs(at))[0]
            np.testing.assert_allclose(got, exact, atol=1e-5)


def test_table_axis_measured_backwards(tmp_path):
    """FB2 X (table) measured from 400 down to 0: the reference is 400 (first position), the
    re-referencing uses the travel from there, not from the smallest position."""
    model = volerr.load("FB2")
    u = np.asarray(model.layout.axes["X"].direction)
    pos = np.linspace(400, 0, 9)
    body = smooth_errors(pos, scale_mm=0.02, scale_rad=80e-6, seed=12)
    pts = simulate("linear", REF, pos, body, direction=-u)
    f = tmp_path / "tracker.csv"
    f.write_text(to_csv([pts], pos, ("P", "Q", "K")))
    assert main(["identify", "FB2", "--axis", "X", str(f), "--signs", "model",
                 "--out", str(tmp_path / "X.csv")]) == 0
    funcs = ErrorFunctions({"X": read_error_table(tmp_path / "X.csv")}, {}, model,
                           method="linear")
    P = np.array([35.0, -80.0, -120.0])
    for k, q in enumerate(pos):
        t, R = body[k, :3], error_rotation(*body[k, 3:])
        moved = (q - pos[0]) * u
        exact = R.T @ (P + moved - t) - (P + moved)
        at = {a: np.array([0.0]) for a in model.axes}
        at["X"] = np.array([q])
        np.testing.assert_allclose(model.volumetric_error(at, funcs(at), probe=P)[0], exact,
                                   atol=1e-5)
