"""Run ``volerr loop DMU50 drift:FILE --holdout-time W --json`` on the six FL windows at 15 s
and 60 s (tests/helpers/fl_runs.py's files) and keep the JSON in benchmarks/research/group_lasso/out/ (the baselines
and the lag model's terms the group lasso is compared with).  Research script, not in the
package."""

import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parents[2] / "tests"))
from helpers.fl_runs import WINDOWS, file_text  # noqa: E402

OUT = HERE / "out"


def main():
    OUT.mkdir(exist_ok=True)
    exe = str(Path(sys.executable).parent / "volerr")   # the volerr of this interpreter
    for step in (1, 4):
        for name, (window, cut) in WINDOWS.items():
            data = OUT / f"fl_{name}_{step}.csv"
            data.write_text(file_text(step, cut))
            js = OUT / f"loop_{name}_{step}.json"
            r = subprocess.run([exe, "loop", "DMU50", f"drift:{data}", "--holdout-time",
                                window, "--json", str(js)], capture_output=True, text=True)
            print(name, step, r.returncode, r.stderr.strip()[:200], flush=True)


if __name__ == "__main__":
    main()
