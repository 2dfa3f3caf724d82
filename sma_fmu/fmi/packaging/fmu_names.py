"""The FMUs of both families by name (from the registry, :mod:`sma_fmu.fmi.models`) and where
the build puts them by default. The registry is read at first use, not at import: the
command line imports this module to build its parser."""
from pathlib import Path

__all__ = ["FMU_SCRIPTS", "DEFAULT_FMU_DIR", "default_fmu_paths"]

DEFAULT_FMU_DIR = Path("fmus")


def _scripts():
    """{model name: its pythonfmu slave script}, in the registry's order."""
    from sma_fmu.fmi.models import declarations

    return {declared.name: declared.slave for declared in declarations()}


def __getattr__(name):
    if name == "FMU_SCRIPTS":   # model name -> its pythonfmu slave script
        return _scripts()
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def default_fmu_paths(out_dir=DEFAULT_FMU_DIR):
    """{model name: path} where the build puts the FMUs."""
    return {name: Path(out_dir) / f"{name}.fmu" for name in _scripts()}
