"""The C family of FMUs, called "native" on the command line (``sma-fmu build --native``):
the runtime in C99 (``runtime/``), the version-neutral core (``core/``: instances, calling
sequence, variables, start values, saved states, log), its two thin FMI fronts (``fmi2/``,
``fmi3/``) and the five model adapters (``models/``), as package data. No Python runs inside
these FMUs; they are built by :mod:`sma_fmu.fmi.packaging.c_family_build`."""
