"""Loads the fits accept, wherever they come from: ``--load``, ``--stress``, a file's stress
column or its header.

The limits lie beyond any Ti-Ni wire's breaking load: a value above them is a unit or a
column mistake, not a test.
"""
__all__ = ["MAX_LOAD_KG", "MAX_STRESS_MPA"]

MAX_LOAD_KG = 10.0          # hung mass [kg]
MAX_STRESS_MPA = 2000.0     # tensile stress [MPa]
