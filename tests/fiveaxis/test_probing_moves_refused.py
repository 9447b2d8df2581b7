"""Probing moves end where the probe touches, which the program does not know: LinuxCNC
G38.2-G38.5, Fanuc / Haas G31 (and G31.1-G31.4) and SINUMERIK MEAS= / MEAW= are refused in one
line naming the construct, never compensated as straight moves (acceptance run
benchmarks/acceptance/nc_programs2)."""

import pytest

import volerr
from volerr.nc import gcode

AXES = ("X", "Y", "Z")


@pytest.mark.parametrize("text,msg", [
    ("G0 X300. Y400. Z150.\nG38.2 Z50. F100.\nG91 G0 Z5.\n", "line 2: G38.2 probe move"),
    ("G0 X300. Y400. Z150.\nG38.3 Z60. F100.\nZ50.\n", "line 2: G38.3 probe move"),
    ("G0 X300. Y400. Z100.\nG38.4 Z120. F100.\n", "line 2: G38.4 probe move"),
    ("G0 X300. Y400. Z100.\ng38.5 z130. f100.\n", "line 2: G38.5 probe move"),
    ("G0 X300. Y400. Z150.\nG31 X500. F200.\nG91 G1 X-2.\n", "line 2: G31 skip"),
    ("G0 X300. Y400. Z150.\nG31.1 X500. F200.\n", "line 2: G31.1 skip"),
    ("G0 X300 Y400 Z150\nMEAS=1 G1 X500 F200\n", "line 2: SINUMERIK MEAS probe move"),
    ("G0 X300 Y400 Z150\nMEAW = 1 G1 X500 F200\n", "line 2: SINUMERIK MEAW probe move"),
])
def test_probing_moves_are_refused_naming_the_construct(text, msg):
    with pytest.raises(volerr.errors.InputError, match=msg):
        gcode.blocks(gcode.parse(text), AXES)
