"""Dump the outputs the speed work must keep byte-identical (branch speedlag).

    python benchmarks/speedlag/dump_outputs.py OUT_DIR [nc] [loop]

nc: for every random program of tests/fiveaxis/test_chunkscan.py (seeds 0-9, orientation off
and on, the whole-chunk path off and on at the chunk sizes the test uses) and the two
tool-vector programs (2500 blocks; Heidenhain/Siemens), the compensated text and the
reports ``(line, status, output)``, one file each.
loop: ``volerr loop`` on the lag acceptance campaigns MB1 day A (3000 points, seed 1) and
DMU50 day A (2000 points, seed 3): the JSON report and every file of --out-dir; the report
also as ``dayA.norm.json`` without its wall time and with the out-dir's path written OUT.
Compare two dumps with ``benchmarks/speedlag/compare.sh A B``.
"""

import contextlib
import io
import os
import re
import sys
from pathlib import Path

for _name in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_name] = "1"
ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "tests"))
sys.path.insert(0, str(ROOT / "tests" / "fiveaxis"))
sys.path.insert(0, str(ROOT / "tests" / "loop"))


def dump_nc(out: Path) -> None:
    import tempfile

    import test_chunkscan as C
    from helpers.error_dirs import write_errors

    import volerr
    from volerr.fiveaxis import program
    from volerr.fiveaxis.program import compensate_program
    from volerr.tables.functions import ErrorFunctions

    m = volerr.load("DMU50")
    d = write_errors(Path(tempfile.mkdtemp()), m, seed=5)
    funcs0 = ErrorFunctions.from_dir(d, m)

    def write(tag, res):
        (out / f"{tag}.txt").write_bytes(res.text.encode("utf-8", "surrogatepass"))
        (out / f"{tag}.reports").write_text(
            "\n".join(repr((r.line, r.status, r.output)) for r in res.reports))

    for seed in range(10):
        text = C.random_program(seed)
        init = {"B": 10.0, "C": 5.0} if seed % 2 else {}
        funcs, kw = funcs0, {}
        if seed >= 8:
            funcs = ErrorFunctions(funcs0.tables, funcs0.constants, m, extrapolate=True)
            kw = {"tool_length": 100.0, "check_travel": False}
        for orientation in (False, True):
            program.WHOLE_CHUNK = False
            write(f"s{seed}_o{int(orientation)}_ref",
                  compensate_program(m, funcs, text, orientation=orientation, initial=init, **kw))
            program.WHOLE_CHUNK = True
            for k in (None, 1, 7, 50) if seed < 8 else (None, 13):
                write(f"s{seed}_o{int(orientation)}_k{k}",
                      compensate_program(m, funcs, text, orientation=orientation,
                                         initial=init, chunk_lines=k, **kw))
    funcs = ErrorFunctions(funcs0.tables, funcs0.constants, m, extrapolate=True)
    for siemens in (False, True):
        text = C.vector_program(m, 4 + siemens, 2500, siemens)
        for k in (None, 997):
            for whole in (False, True):
                program.WHOLE_CHUNK = whole
                write(f"vec{int(siemens)}_k{k}_w{int(whole)}",
                      compensate_program(m, funcs, text, chunk_lines=k, tool_length=100.0,
                                         check_travel=False))


def dump_loop(out: Path) -> None:
    import test_lag_acceptance as L
    from helpers import thermal_sim as T

    for name, layout, plant, n, seed in (("mb1", "MB1", L.MB1_PLANT, 3000, 1),
                                         ("dmu50", "DMU50", L.DMU_PLANT, 2000, 3)):
        folder = out / name
        folder.mkdir(parents=True, exist_ok=True)
        camp = T.campaign(layout, T.DAY_A, plant, n=n, seed=seed)
        run = L.Run(layout, camp.write(folder / "dayA.csv"), folder, "dayA")
        assert run.rc == 0, run.stderr
        # the report without its wall time ("seconds") and with the out-dir's path as OUT:
        # what must stay byte-identical
        text = run.json_path.read_text().replace(str(run.out_dir), "OUT")
        text = re.sub(r'\n *"seconds": [0-9.eE+-]+,?', "", text)
        run.json_path.with_suffix(".norm.json").write_text(text)


if __name__ == "__main__":
    out = Path(sys.argv[1])
    out.mkdir(parents=True, exist_ok=True)
    what = sys.argv[2:] or ["nc", "loop"]
    if "nc" in what:
        (out / "nc").mkdir(exist_ok=True)
        dump_nc(out / "nc")
    if "loop" in what:
        dump_loop(out / "loop")
