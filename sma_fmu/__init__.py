"""sma-fmu: SMA wire actuator model, feedforward hysteresis compensator and FMI co-simulation units.

The physics lives in :mod:`sma_fmu.runtime` (standard library only, shipped in the FMUs);
parameter files are read by :mod:`sma_fmu.parameter_file`.
"""
__version__ = "0.1.0"

from .parameter_file import load_parameters, load_parameter_set  # noqa: E402

__all__ = ["__version__", "load_parameters", "load_parameter_set"]
