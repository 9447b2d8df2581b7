"""Audit support in the runtime: the printed equations (data files) evaluated numerically
against the generated models, without sympy.
"""

