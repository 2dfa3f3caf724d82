"""FMI glue: building the FMUs, the code they ship, and driving FMUs from Python.

- :mod:`sma_fmu.fmi.build`: builds the FMUs with pythonfmu and validates them with fmpy;
- :mod:`sma_fmu.fmi.instance`: one FMU instance driven through fmpy, variables by name;
- ``slave_support/``: the FMI plumbing every FMU ships (pythonfmu + standard library);
- ``slaves/``: the slave scripts, one per FMU (package data, built into FMUs, not imported).
"""
