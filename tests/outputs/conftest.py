"""Shared inputs of the output-safety tests: small, built once per session."""

from __future__ import annotations

import pytest


@pytest.fixture(scope="session")
def inputs(tmp_path_factory):
    """Paths of one valid input of every kind a command reads."""
    from volerr.cmm.examples import write_example_errors
    from volerr.fiveaxis.example import write_example
    from volerr.identify.tracker_io import example_path
    from volerr.probe.plans import simulate_demo_sphere

    d = tmp_path_factory.mktemp("inputs")
    write_example_errors(d / "errors_MB1", "MB1")
    ex = write_example(d / "dmu50", "DMU50")
    sphere = simulate_demo_sphere(d / "sphere.csv")
    run = d / "run.csv"
    lines = ["target_mm,cycle,direction,deviation_um"]
    for i, t in enumerate(range(0, 901, 150)):
        for c in (1, 2, 3):
            for word, off in (("+1", 1.0), ("-1", -1.0)):
                lines.append(f"{t},{c},{word},{0.01 * t + off + 0.1 * c}")
    run.write_text("\n".join(lines) + "\n")
    task = d / "task.csv"
    task.write_text("X,Y,Z\n100,100,100\n300,100,100\n")
    gcode = d / "prog.nc"
    gcode.write_text("G90\nG1 X10 Y10 Z50 B0 C0\nG1 X20 Y10 Z50 B10 C20\n")
    from importlib import resources

    data = resources.files("volerr") / "data"
    return {"dir": d, "errors": d / "errors_MB1", "dmu_errors": ex["errors"],
            "ballbar": data / "ballbar_example_XY.csv",
            "sphere_probing": data / "sphere_example_DMU50.csv",
            "program": ex["program"], "small_program": gcode, "tracker": example_path("X"),
            "sphere": sphere["path"], "sphere_r": sphere["sphere_radius_mm"], "run": run,
            "task": task}
