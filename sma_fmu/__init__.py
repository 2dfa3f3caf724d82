"""sma-fmu: SMA wire actuator model, feedforward hysteresis compensator and FMI co-simulation units.

Subpackages, by concern:
- :mod:`sma_fmu.runtime`: the physics and steppers (standard library only, shipped in the FMUs);
- :mod:`sma_fmu.fmi`: building FMUs, the FMI glue they ship, driving FMUs from Python;
- :mod:`sma_fmu.cosim`: scenarios, the closed loop, the fmpy master, metrics, results, figures;
- :mod:`sma_fmu.identification`: parameter identification from measurements;
- :mod:`sma_fmu.analysis`: the best tracking any controller can reach (lower bound, benchmark);
- :mod:`sma_fmu.cli`: the ``sma-fmu`` command line.
Parameter files are read by :mod:`sma_fmu.parameter_file`; the shipped data (``models/``,
``scenarios/``, ``examples/``, ``fmi/slaves/``) is found by :mod:`sma_fmu.package_data`.
"""
__version__ = "0.1.0"

from sma_fmu.parameter_file import load_parameters, load_parameter_set  # noqa: E402

__all__ = ["__version__", "load_parameters", "load_parameter_set"]
