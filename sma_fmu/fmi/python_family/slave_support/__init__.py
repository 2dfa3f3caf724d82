"""The FMI plumbing shipped inside every FMU: variables with units, guards, model description.

Imports only the standard library, pythonfmu (which every pythonfmu FMU carries) and
:mod:`sma_fmu.runtime`. The build copies this package into each FMU under a stamped name.
"""
