"""Example input files for every command (``volerr examples --out DIR``).

The files shipped in the package (``volerr/data``: laser-tracker runs, a sphere probing run, a
ballbar circle) are copied; the rest are the built-in campaigns of ``volerr demo`` written
afresh (error tables, a five-axis program, instrument files of known truth, a positioning
run, a thermal drift test, an uncertainty task), all simulated.  :data:`EXAMPLES` lists every
file with what it is and a command that reads it; ``DIR/README.txt`` says the same.
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
    "drift_spindle.csv": ("ISO 230-3 spindle drift test (simulated): five sensors round a "
                          "test mandrel (X and Y at two heights, Z), the spindle programme, "
                          "three temperatures",
                          "volerr iso230-3 drift_spindle.csv --html drift_spindle.html"),
    "drift_logger_raw.csv": ("the same test as a logger saves it (Time(min), ch1(um), "
                             "t1(°C), spindle(RPM))",
                             "volerr drift convert drift_logger_raw.csv --out drift.csv "
                             "--channel 'ch1=X at z=20' --channel 'ch2=Z'"),
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


def drift_spindle_columns(hours: float = 9.0, step_s: float = 30.0) -> dict:
    """A simulated spindle drift test (ISO 230-3): at rest 0.5 h, 3000 rpm for 2 h, stop 1 h,
    6000 rpm 2 h, stop; the loss ``P = (S / 6000) ** 1.5`` heats the bearings (``T_spindle``:
    12 K x P through a 15 min lag) and the motor (``T_motor``: 8 K x P, 5 min) above the room
    (``T_room``: 0.4 K swing); the headstock follows the bearings through a 20 min lag ``h``
    (K above the start): the tool point moves by -1.2 um/K x h along Z (the spindle grows
    towards the table), 0.25 um/K along X, and the spindle tilts 1.5 urad/K about +Y, 0.5
    about +X; sensors X and Y at z = 20 and 120 mm (Y read along -Y), 0.1 um noise.
    Columns of the drift format (:mod:`volerr.instruments.drift`)."""
    import numpy as np

    rng = np.random.default_rng(7)
    t = np.arange(0.0, hours * 3600 + step_s / 2, step_s)
    hr = t / 3600.0
    s = np.select([hr < 0.5, hr < 2.5, hr < 3.5, hr < 5.5], [0.0, 3000.0, 0.0, 6000.0], 0.0)

    def lag(u, tau):                    # first-order lag, the input held over each step
        a, y = np.exp(-step_s / tau), np.empty_like(u)
        y[0] = u[0]
        for k in range(1, len(u)):
            y[k] = a * y[k - 1] + (1 - a) * u[k - 1]
        return y

    p = (s / 6000.0) ** 1.5
    room = 20.5 + 0.4 * np.sin(2 * np.pi * t / (10 * 3600))
    spindle, motor = room + 12 * lag(p, 900.0), room + 8 * lag(p, 300.0)
    h = lag(spindle, 1200.0) - spindle[0]
    beta, alpha = 1.5 * h, 0.5 * h                              # urad about +Y, +X
    noise = lambda: rng.normal(0.0, 0.1, len(t))                # noqa: E731
    out = {"t_s": t, "S_rpm": s}
    for z, tag in ((20.0, "1"), (120.0, "2")):
        out[f"d_x{tag}_um"] = 0.25 * h + beta * z * 1e-3 + noise()
        out[f"d_y{tag}_um"] = alpha * z * 1e-3 + noise()       # -Y reads +alpha z
    out["d_z_um"] = -1.2 * h + noise()
    out.update(T_spindle=spindle + rng.normal(0, 0.01, len(t)),
               T_motor=motor + rng.normal(0, 0.01, len(t)),
               T_room=room + rng.normal(0, 0.01, len(t)))
    return out


def write_drift_examples(folder) -> None:
    """``drift_spindle.csv`` (drift format) and ``drift_logger_raw.csv`` (a logger's names,
    minutes) of :func:`drift_spindle_columns`."""
    import numpy as np

    from .fileio import write_text

    cols = drift_spindle_columns()
    head = ["# simulated ISO 230-3 spindle drift test (volerr examples)",
            "# channel d_x1: X at z=20", "# channel d_x2: X at z=120",
            "# channel d_y1: -Y at z=20", "# channel d_y2: -Y at z=120", "# channel d_z: Z"]
    names = ["t_s", "S_rpm", "d_x1_um", "d_x2_um", "d_y1_um", "d_y2_um", "d_z_um",
             "T_spindle", "T_motor", "T_room"]
    rows = np.column_stack([cols[k] for k in names])
    body = [",".join(f"{v:.4f}".rstrip("0").rstrip(".") for v in r) for r in rows]
    write_text(Path(folder) / "drift_spindle.csv", "\n".join(head + [",".join(names)] + body)
               + "\n")
    raw = ["Time(min),ch1(um),ch2(um),t1(°C),t2(°C),spindle(RPM)"]
    raw += [f"{t / 60:g},{x:.3f},{z:.3f},{a:.3f},{b:.3f},{s:g}" for t, x, z, a, b, s in zip(
        cols["t_s"], cols["d_x1_um"], cols["d_z_um"], cols["T_spindle"], cols["T_room"],
        cols["S_rpm"])]
    write_text(Path(folder) / "drift_logger_raw.csv", "\n".join(raw) + "\n")


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
    write_drift_examples(d)
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
