"""The C family of FMUs, called "native" on the command line (``sma-fmu build --native``):
the runtime in C99 (``runtime/``), the version-neutral core (``core/``: instances, calling
sequence, variables, start values, saved states, log), its two thin FMI fronts (``fmi2/``,
``fmi3/``) and what the model adapters share (``adapter_support/``: the wire parameters, the
choice codes), as package data; each adapter lies in its FMU's folder (``fmi/models/<Model>/``).
No Python runs inside these FMUs; they are built by
:mod:`sma_fmu.fmi.packaging.c_family_build`."""
