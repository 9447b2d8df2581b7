"""Example input files for every command (``volerr examples --out DIR``).

The files shipped in the package (``volerr/data``: laser-tracker runs, a sphere probing run, a
ballbar circle) are copied; the rest are the built-in campaigns of ``volerr demo`` written
afresh (error tables, a five-axis program, instrument files of known truth, a positioning
run, an uncertainty task), all simulated.  :data:`EXAMPLES` lists every file with what it is
and a command that reads it; ``DIR/README.txt`` says the same.
"""

from __future__ import annotations

from importlib import resources
from pathlib import Path

#: the files shipped in volerr/data that are example inputs
SHIPPED = ("tracker_example_X.csv", "tracker_example_Y.csv", "tracker_example_Z.csv",
           "sphere_example_DMU50.csv", "ballbar_example_XY.csv")

#: relative path -> (what it is, a command that reads it, run in DIR)
EXAMPLES = {
    "tracker_example_X.csv": ("laser-tracker three-point data of MB1's X axis (shipped)",
                              "volerr identify MB1 --axis X tracker_example_X.csv "
                              "--errors-out tracker_X"),
    "tracker_example_Y.csv": ("the same for Y (shipped)",
                              "volerr identify MB1 --axis Y tracker_example_Y.csv "
                              "--errors-out tracker_Y"),
    "tracker_example_Z.csv": ("the same for Z (shipped)",
                              "volerr identify MB1 --axis Z tracker_example_Z.csv "
                              "--errors-out tracker_Z"),
    "sphere_example_DMU50.csv": ("touch-probe sphere cycle on the DMU50 (shipped)",
                                 "volerr calibrate DMU50 sphere_example_DMU50.csv"),
    "ballbar_example_XY.csv": ("ISO 230-4 ballbar circle in XY on MB1 (shipped)",
                               "volerr ballbar evaluate ballbar_example_XY.csv"),
    "errors_MB1/": ("example error tables of Pahk's CMM A (MB1)",
                    "volerr map MB1 --errors errors_MB1"),
    "dmu50/errors/": ("synthetic error tables of the DMU50",
                      "volerr tcpmap DMU50 --errors dmu50/errors --point 30 20 60 "
                      "--plot tcpmap.png"),
    "dmu50/hemisphere.nc": ("hemisphere finishing program, DMU50 machine axes (ISO G-code)",
                            "volerr compensate DMU50 --errors dmu50/errors dmu50/hemisphere.nc "
                            "--out hemisphere_compensated.nc"),
    "ballbar/": ("three ballbar circles XY, YZ, ZX of MB1 (planted squareness and scales) "
                 "and their error directory",
                 "volerr calibrate MB1 ballbar/ballbar_XY.csv ballbar/ballbar_YZ.csv "
                 "ballbar/ballbar_ZX.csv"),
    "ballplate_MB1.csv": ("5 x 5 ball plate in four placements on MB1",
                          "volerr calibrate MB1 ballplate_MB1.csv --parameters "
                          "EXX,EYY,EZZ,EC0Y,EB0Z,EA0Z --degree 1"),
    "multilateration_DMU50.csv": ("tracking interferometer, four stations, DMU50",
                                  "volerr calibrate DMU50 multilateration_DMU50.csv"),
    "probe_sphere.csv": ("master-sphere probing, Pahk's 101-point plan (sphere radius "
                         "25.006 mm)",
                         "volerr probe-cal probe_sphere.csv --sphere-radius 25.006 "
                         "--out probe_map.csv"),
    "deviations_MB1.csv": ("measured volumetric deviations of a virtual MB1 with an "
                           "undeclared thermal effect",
                           "volerr loop MB1 deviations_MB1.csv"),
    "iso230_2_run_X.csv": ("laser-interferometer positioning run of X (ISO 230-2)",
                           "volerr iso230-2 iso230_2_run_X.csv"),
    "task_distance.csv": ("uncertainty task: a 400 mm distance",
                          "volerr uncertainty MH2 --task task_distance.csv --evaluate "
                          "distance --spec E0=2+L/300"),
}


def known_files() -> list:
    """The example files whose names are known before writing (not those in folders)."""
    return [name for name in EXAMPLES if not name.endswith("/")] + ["README.txt"]


def shipped_path(name: str):
    """The path of a shipped example file in the installed package."""
    return resources.files("volerr") / "data" / name


def write_iso230_2_run(path) -> None:
    """A positioning run of X: 9 targets over 800 mm, 5 cycles, both directions (um)."""
    import numpy as np

    from .fileio import write_text

    rng = np.random.default_rng(2)
    lines = ["target_mm,cycle,direction,deviation_um"]
    for t in np.linspace(0.0, 800.0, 9):
        base = 4.0 * np.sin(t / 200.0) + 0.005 * t
        for c in range(1, 6):
            for word, half in (("+1", 1.2), ("-1", -1.2)):
                lines.append(f"{t:g},{c},{word},{base + half + rng.normal(0, 0.3):.4f}")
    write_text(path, "\n".join(lines) + "\n")


def write_examples(folder) -> list:
    """Write every example of :data:`EXAMPLES` and ``README.txt`` into ``folder`` (which must
    exist); returns the relative paths written."""
    from .calibrate.examples import (write_ballbar_example, write_ballplate_example,
                                     write_multilateration_example)
    from .cmm.examples import write_example_errors
    from .fileio import write_bytes, write_text
    from .fiveaxis.example import write_example
    from .loop.run import demo_campaign
    from .probe.plans import simulate_demo_sphere

    d = Path(folder)
    for name in SHIPPED:
        write_bytes(d / name, shipped_path(name).read_bytes())
    write_example_errors(d / "errors_MB1", "MB1")
    write_example(d / "dmu50", "DMU50")
    write_ballbar_example(d / "ballbar")
    write_ballplate_example(d / "ballplate_MB1.csv", "MB1")
    write_multilateration_example(d / "multilateration_DMU50.csv", "DMU50", n=60)
    simulate_demo_sphere(d / "probe_sphere.csv")
    demo_campaign(d / "deviations_MB1.csv", n_points=400)
    write_iso230_2_run(d / "iso230_2_run_X.csv")
    write_text(d / "task_distance.csv", "X,Y,Z\n100,200,150\n500,200,150\n")
    write_text(d / "README.txt", readme())
    return sorted(str(p.relative_to(d)) for p in d.rglob("*") if p.is_file())


def readme() -> str:
    """README.txt of the example folder: every file, what it is and a command reading it."""
    lines = ["volerr example files (simulated data; file formats: 'volerr formats').",
             "Run the commands in this folder.", ""]
    for name, (what, command) in EXAMPLES.items():
        lines += [f"{name}", f"    {what}", f"    $ {command}", ""]
    return "\n".join(lines)
