"""The FMUs of both families by name (from the registry, :mod:`sma_fmu.fmi.models`) and where
the build puts them by default."""
from pathlib import Path

from sma_fmu.fmi.models import declarations

__all__ = ["FMU_SCRIPTS", "DEFAULT_FMU_DIR", "default_fmu_paths"]

# model name -> its pythonfmu slave script, in the registry's order
FMU_SCRIPTS = {declared.name: declared.slave for declared in declarations()}
DEFAULT_FMU_DIR = Path("fmus")


def default_fmu_paths(out_dir=DEFAULT_FMU_DIR):
    """{model name: path} where the build puts the FMUs."""
    return {name: Path(out_dir) / f"{name}.fmu" for name in FMU_SCRIPTS}
