"""Benchmark of ``volerr calibrate`` on a mixed campaign of ~10^5 readings (issue 19: under 20 s
on the 2-core machine), with the ratio to fitting each file alone.

DMU50, as a calibration lab would combine its instruments: a file of 3-D deviations of the
tool point (a tracker or a CMM against a reference: 20 000 poses x 3 readings, three tool
offsets), three ballbar circles (XY, YZ, ZX, both directions: 3 x 6000 readings) and a sphere
probing file (two placements, B and C over their travel, repeated: ~8 000 poses x 3 readings);
all parameters fitted (component series of degree 3, constants, set-ups).  The files are
written as users have them (CSV); each ``volerr calibrate`` runs as a whole process (reading
included): CPU and wall time, peak RSS of the child.  Baseline in the same session: the same
command on each file alone (their sum: what separate fits cost).

    python benchmarks/bench_calibrate.py [--scale F]    (F multiplies the sizes; default 1)
"""

import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import volerr
from volerr.instruments.ballbar import simulate as ballbar_trace
from volerr.instruments.ballbar import write_csv as write_ballbar
from volerr.calibrate.examples import SPHERE_TRUTH
from volerr.instruments import sphere
from volerr.tables.functions import ErrorFunctions


def campaign(folder: Path, scale: float) -> list:
    model = volerr.load("DMU50")
    rng = np.random.default_rng(5)
    truth = {k: v * (1e-6 if k[1] in "ABC" else 1e-3) for k, v in SPHERE_TRUTH.items()}
    truth.update({"EC0Y": 12e-6, "EB0Z": -8e-6, "EA0Z": 5e-6})
    files = []
    # 3-D deviations over the volume, rotary axes fixed at 0
    n = int(20000 * scale)
    pos = {a: rng.uniform(*model.travel[a], n) for a in ("X", "Y", "Z")}
    pos.update({"B": np.zeros(n), "C": np.zeros(n)})
    probe = np.array([(0, 0, 100), (50, 0, 120), (0, 50, 80)], float)[rng.integers(0, 3, n)]
    e = model.volumetric_error(pos, truth, probe=probe) + rng.normal(0, 0.5e-3, (n, 3))
    cols = {**pos, "Xp": probe[:, 0], "Yp": probe[:, 1], "Zp": probe[:, 2],
            "dx_um": 1e3 * e[:, 0], "dy_um": 1e3 * e[:, 1], "dz_um": 1e3 * e[:, 2]}
    path = folder / "tracker_deviations.csv"
    _write(path, cols)
    files.append(path)
    funcs = ErrorFunctions({}, truth, model)
    for plane in ("XY", "YZ", "ZX"):
        cols = ballbar_trace(model, funcs, plane, 100.0, (0.0, 0.0, 250.0), (0, 0, 100),
                             {"B": 0.0, "C": 0.0}, int(3000 * scale), 0.3, "both")
        path = folder / f"ballbar_{plane}.csv"
        write_ballbar(path, cols)
        files.append(path)
    rotary = {"B": np.linspace(0, 180, 37), "C": np.linspace(0, 350, 36)}
    poses = sphere.plan(model, [(80.0, 40.0, 20.0), (-60.0, 70.0, 90.0)], rotary, (0, 0, 120))
    reps = max(1, int(round(8000 * scale / len(poses["placement"]))))
    parts = [sphere.simulate(model, truth, poses, (0, 0, 120), noise_um=0.5, seed=s)
             for s in range(reps)]
    cols = {k: np.concatenate([p[k] for p in parts]) for k in parts[0]}
    path = folder / "sphere_probing.csv"
    sphere.write_csv(path, cols)
    files.append(path)
    return files


def _write(path: Path, cols: dict) -> None:
    names = list(cols)
    data = np.column_stack([cols[k] for k in names])
    np.savetxt(path, data, delimiter=",", header=",".join(names), comments="", fmt="%.6f")


def readings(path: Path) -> int:
    with open(path) as fh:
        header = fh.readline().lower()
        rows = sum(1 for _ in fh)
    return rows * (1 if "pivot_x" in header else 3)


def run(files, folder: Path, tag: str) -> tuple[float, float, float]:
    """(wall s, CPU s, peak RSS MB) of one ``volerr calibrate`` process."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    r = subprocess.run([sys.executable, "-m", "volerr", "calibrate", "DMU50", *map(str, files),
                        "--json", str(folder / f"{tag}.json"), "--degree", "3"],
                       capture_output=True, text=True)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if r.returncode:
        raise SystemExit(r.stderr)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return wall, cpu, after.ru_maxrss / 1024


def main() -> None:
    scale = float(sys.argv[sys.argv.index("--scale") + 1]) if "--scale" in sys.argv else 1.0
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        files = campaign(folder, scale)
        total = sum(readings(f) for f in files)
        wall, cpu, rss = run(files, folder, "mixed")
        alone = [run([f], folder, f"alone_{i}") for i, f in enumerate(files)]
        sum_wall = sum(a[0] for a in alone)
        sum_cpu = sum(a[1] for a in alone)
        print(f"campaign: {len(files)} files, {total} readings "
              f"({', '.join(f'{f.name} {readings(f)}' for f in files)})")
        print(f"calibrate, all files in one fit: wall {wall:.2f} s, CPU {cpu:.2f} s, "
              f"peak RSS {rss:.0f} MB (target < 20 s)")
        print(f"each file alone: wall {sum_wall:.2f} s, CPU {sum_cpu:.2f} s in total "
              f"({', '.join(f'{a[0]:.2f}' for a in alone)} s); ratio mixed / sum of alone "
              f"{wall / sum_wall:.2f} (wall), {cpu / sum_cpu:.2f} (CPU)")


if __name__ == "__main__":
    main()
