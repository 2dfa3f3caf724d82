"""The closed loop in system-level tools: SSP packages, a container FMU, hosts, compliance checks.

- :mod:`.closed_loop`: a scenario's loop as components, parameter values and connections;
- :mod:`.ssp`: the SSP 1.0 package (SystemStructure.ssd + the FMUs);
- :mod:`.container`: the whole loop as one FMI 2.0 FMU (fmu-manipulation-toolbox);
- :mod:`.hosts`: running them in libcosim, Ecos and fmpy, results as loop time series;
- :mod:`.check`: the compliance check behind ``sma-fmu check``.
"""
