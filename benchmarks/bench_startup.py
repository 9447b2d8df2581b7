"""Benchmark: start-up of ``python -m volerr`` (issue 42 item 7), this tree against a baseline.

Every ``volerr --help``, ``volerr CMD --help``, a usage error and a small command is a fresh
interpreter importing ``volerr.cli``, which builds the parser of every command.  Measured: CPU
seconds (user + sys of the child) of a few such start-ups, this tree and the baseline commit
interleaved, min and median of the runs; and the help texts of every command compared byte for
byte (they must not change).  The suite starts ~300 of these processes (the history race test
alone ~50), so each 0.1 s is ~30 s of the suite's CPU.

Run: python benchmarks/bench_startup.py [--base REV] [--runs R]   (default 5daa8fe, 7 runs)
"""

import argparse
import json
import resource
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _baseline import env_for, export, which_volerr  # noqa: E402

#: the commit before the parsers were built without importing the capabilities
BASE = "5daa8fe"

HELP_TEXTS = """
import argparse, contextlib, io, json, volerr.cli as c
p = c.build_parser()
sub = next(a for a in p._actions if isinstance(a, argparse._SubParsersAction))
out = {}
def run(argv):
    f, e = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(f), contextlib.redirect_stderr(e):
        code = c.main(argv)
    out[" ".join(argv)] = [code, f.getvalue(), e.getvalue()]
run(["--help"]); run(["calibrat"]); run(["map", "--jsn", "x"])
for n, sp in sub.choices.items():
    run([n, "--help"])
    for a in sp._actions:
        if isinstance(a, argparse._SubParsersAction):
            for m in a.choices:
                run([n, m, "--help"])
print(json.dumps(out))
"""


def cpu_of(args, pythonpath, cwd) -> float:
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run([sys.executable, *args], capture_output=True, env=env_for(pythonpath),
                   cwd=cwd)
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime)


def main(base: str = BASE, runs: int = 7) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        d = Path(tmp)
        pkg = export(base, d / "base")
        assert which_volerr(pkg).startswith(str(pkg)), "baseline import not taken"
        cal = d / "cal.json"
        cal.write_text(json.dumps({"layout": "DMU50", "unidentifiable": [], "parameters": {
            "EX0C": {"value": 1.0, "unit": "um", "std": 0.1}}}))
        jobs = {"volerr --help": ["--help"], "volerr history add --help": ["history", "add", "--help"],
                "volerr calibrate --help": ["calibrate", "--help"], "volerr layouts": ["layouts"],
                "volerr formats tables": ["formats", "tables"],
                "volerr history add (new SQLite file)": ["history", "add", "--machine", "M1",
                                                         "--date", "2025-03-03", str(cal), "--db"]}
        print(f"this tree vs {base}: {runs} runs each, interleaved; CPU s = user + sys of the "
              f"child; min / median")
        for title, args in jobs.items():
            res = {"new": [], "base": []}
            for i in range(runs):
                for tag, path in (("new", None), ("base", pkg)):
                    extra = [str(d / f"h_{tag}{i}.sqlite")] if args[-1] == "--db" else []
                    res[tag].append(cpu_of(["-m", "volerr", *args, *extra], path, d))
            new, old = res["new"], res["base"]
            print(f"  {title:40s} this tree {min(new):.3f} / {statistics.median(new):.3f}   "
                  f"{base} {min(old):.3f} / {statistics.median(old):.3f}   ratio (medians) "
                  f"{statistics.median(old) / statistics.median(new):.2f} x")
        texts = [subprocess.run([sys.executable, "-c", HELP_TEXTS], capture_output=True,
                                text=True, env=env_for(path), cwd=d, check=True).stdout
                 for path in (None, pkg)]
        same = json.loads(texts[0]) == json.loads(texts[1])
        print(f"  help texts, usage errors and exit codes of every command identical: {same} "
              f"({len(json.loads(texts[0]))} compared)")
        assert same


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--base", default=BASE, help="baseline commit (default %(default)s)")
    ap.add_argument("--runs", type=int, default=7, help="runs of each (default %(default)s)")
    a = ap.parse_args()
    main(a.base, a.runs)
