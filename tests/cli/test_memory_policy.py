"""The command's malloc policy: blocks freed by one step of a block-wise evaluation are reused
by the next instead of being returned to the system and faulted in again."""

import subprocess
import sys

import pytest

CHILD = """
import resource, sys
import numpy as np
if sys.argv[1] == "1":
    from volerr.cli._memory import keep_freed_blocks
    assert keep_freed_blocks()
a = np.ones(2 ** 17)   # warm up numpy's own allocations
before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
for _ in range(200):   # a block's temporaries: 1 MB arrays made and freed
    t = [np.ones(2 ** 17) for _ in range(4)]
    del t
print(resource.getrusage(resource.RUSAGE_SELF).ru_minflt - before)
"""


def faults(policy: str) -> int:
    out = subprocess.run([sys.executable, "-c", CHILD, policy], capture_output=True, text=True,
                         check=True)
    return int(out.stdout.split()[-1])


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="glibc malloc policy")
def test_freed_blocks_are_reused_not_faulted_in_again():
    plain, kept = faults("0"), faults("1")
    # 200 rounds x 4 MB: without the policy every round faults its pages in again (~1000 per
    # round); with it the first round's pages are reused
    assert plain > 50_000
    assert kept < plain / 20
