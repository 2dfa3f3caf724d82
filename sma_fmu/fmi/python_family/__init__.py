"""The Python family of FMUs: pythonfmu slaves over the standard-library runtime (each slave
script lies in its FMU's folder, ``fmi/models/<Model>/``).

- :mod:`.slave_support`: the FMI glue every FMU of this family ships (pythonfmu + stdlib);
- ``front/``: the C sources of the front, the FMU's binary in front of pythonfmu's
  (compiled by :mod:`sma_fmu.fmi.packaging.front_build`).
"""
