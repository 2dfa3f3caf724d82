"""Where the project's data folders are: models/, fmu_src/, scenarios/.

In a source checkout (editable install) they sit next to the package; a regular
install carries them as the package data ``sma_fmu.models`` etc.
"""
from importlib import resources
from pathlib import Path

__all__ = ["project_folder", "default_parameter_file"]

_CHECKOUT = Path(__file__).resolve().parent.parent

DEFAULT_PARAMETER_FILE_NAME = "reference_wire.toml"


def project_folder(name):
    """Path of the project folder ``name`` ("models", "fmu_src" or "scenarios")."""
    in_checkout = _CHECKOUT / name
    if in_checkout.is_dir():
        return in_checkout
    try:
        return Path(str(resources.files(f"sma_fmu.{name}")))
    except ModuleNotFoundError:
        raise FileNotFoundError(f"project folder {name!r} is neither in the checkout "
                                f"({in_checkout}) nor installed as sma_fmu.{name}") from None


def default_parameter_file():
    """The reference wire's parameter file."""
    return project_folder("models") / DEFAULT_PARAMETER_FILE_NAME
