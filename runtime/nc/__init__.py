"""NC programs, without any error model: the dialects (ISO G-code :mod:`~volerr.nc.gcode`,
Heidenhain plain language :mod:`~volerr.nc.heidenhain`, detected by :mod:`~volerr.nc.dialect`),
the whole-chunk scan (:mod:`~volerr.nc.chunkscan`), the program model (:mod:`~volerr.nc.interpret`:
motion blocks and modal state; arcs :mod:`~volerr.nc.arcs`; TCPM frames and tool tables
:mod:`~volerr.nc.tcpm`) and the writer of a program with new numbers (:mod:`~volerr.nc.writer`).

It imports nothing of the machines or the error models; :mod:`volerr.fiveaxis` (kinematics,
compensation) uses it.
"""
