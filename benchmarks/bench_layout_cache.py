"""Benchmark: a command on a layout FILE vs the shipped layout, with the derivation cache.

Each load runs in a fresh process (what a user's command does): the shipped DMU50 module,
the same layout as a file with an empty cache (derived with sympy), and again (read from the
cache).  Interleaved, min of the runs.

Run: python benchmarks/bench_layout_cache.py [LAYOUT]   (default DMU50)
"""

import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import volerr

CODE = ("import sys, volerr; m = volerr.load(sys.argv[1]); "
        "m.volumetric_error([[0.0] * len(m.axes)]); print('sympy' in sys.modules)")


def timed(arg, cache) -> tuple[float, bool]:
    env = {**os.environ, "VOLERR_CACHE_DIR": str(cache)}
    t0 = time.perf_counter()
    r = subprocess.run([sys.executable, "-c", CODE, str(arg)], capture_output=True, text=True,
                       env=env, check=True)
    return time.perf_counter() - t0, r.stdout.strip() == "True"


def main(name: str = "DMU50") -> None:
    src = Path(volerr.__file__).parent / "layouts" / f"{name}.toml"
    with tempfile.TemporaryDirectory() as tmp:
        f = Path(tmp) / "custom.toml"
        f.write_text(src.read_text().replace(f'name = "{name}"', 'name = "CUSTOM"'))
        cold, _ = timed(f, Path(tmp) / "cache")
        shipped, cached = [], []
        for _ in range(3):
            shipped.append(timed(name, Path(tmp) / "cache")[0])
            t, used_sympy = timed(f, Path(tmp) / "cache")
            assert not used_sympy
            cached.append(t)
        print(f"{name} as a layout file: first load {cold:.2f} s (derived), second load "
              f"{min(cached):.2f} s (cache, no sympy) vs shipped {min(shipped):.2f} s: ratio "
              f"{min(cached) / min(shipped):.2f}x (was {cold / min(shipped):.0f}x)")


if __name__ == "__main__":
    if {"-h", "--help"} & set(sys.argv[1:]):     # the usage is the docstring
        sys.exit(print(__doc__))
    main(*sys.argv[1:2])
