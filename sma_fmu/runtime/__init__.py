"""Runtime physics of sma-fmu: standard library only (``math``), shipped inside the FMUs.

Modules, by section of the model specification:
constants, checks, parameters (schema), lattice (1), phases (2), constant_load (3-4),
sensing (5), minor_loops (6), constant_temperature (7), constant_length (8),
thermal (9), phase_lag and pi_control (10), plant and feedforward (the steppers),
signals (the scenario signals R_ref(t) and load(t)) and stroke (a stroke reference mapped
to R_ref through the model).
Nothing here may import numpy, scipy, pythonfmu or anything outside the standard library;
the FMI glue the FMUs also ship is in :mod:`sma_fmu.fmi.python_family.slave_support`.
"""
