"""sma-fmu: SMA wire actuator model, feedforward hysteresis compensator and FMI co-simulation units.

Subpackages, by concern, lowest layer first (each imports only from those before it;
tests/project/test_layout.py checks it):
- :mod:`sma_fmu.runtime`: the physics and steppers (standard library only, shipped in the FMUs);
- :mod:`sma_fmu.console`: progress bars, Ctrl-C, the extra a command needs (what the user
  sees besides results);
- :mod:`sma_fmu.files`: shipped data, TOML and JSON files, output folders never left half-written;
- :mod:`sma_fmu.wire`: parameter files and the parameters derived from a wire's geometry;
- :mod:`sma_fmu.fmi`: building FMUs, the FMI glue they ship, driving FMUs from Python;
- :mod:`sma_fmu.cosim`: scenarios, the closed loop, the fmpy master, metrics, reports, figures;
- :mod:`sma_fmu.systems`: the loop in system tools (SSP, container, hosts) and the runner
  that writes a scenario's results on any path;
- :mod:`sma_fmu.studies`, :mod:`sma_fmu.analysis`, :mod:`sma_fmu.identification`: design
  studies on the batch engine, the best possible tracking, parameter identification;
- :mod:`sma_fmu.bench`: ``sma-fmu bench``;
- :mod:`sma_fmu.cli`: the ``sma-fmu`` command line.
"""
__version__ = "0.1.0"

__all__ = ["__version__", "load_parameters", "load_parameter_set"]


def __getattr__(name):
    """``load_parameters`` and ``load_parameter_set``, imported at first use: importing the
    package (``sma-fmu --version``, every command's start) stays cheap."""
    if name in ("load_parameters", "load_parameter_set"):
        from sma_fmu.wire import parameter_file
        return getattr(parameter_file, name)
    raise AttributeError(f"module 'sma_fmu' has no attribute {name!r}")
