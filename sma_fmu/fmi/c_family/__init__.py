"""The C family of FMUs, called "native" on the command line (``sma-fmu build --native``):
the runtime in C99 (``runtime/``), the FMI 2.0 layer (``fmi2/``) and the five model adapters
(``models/``), as package data. No Python runs inside these FMUs; they are built by
:mod:`sma_fmu.fmi.packaging.c_family_build`."""
