"""The data files shipped inside the package: parameter files, scenarios, examples.

They live in the package (``sma_fmu/models``, ``sma_fmu/scenarios``, ``sma_fmu/examples``)
so that a checkout, an editable install, a wheel and an sdist all find them the same way:
through :mod:`importlib.resources`, opened as real files with ``as_file`` (never by turning
a resource object's text into a path).
"""
import atexit
import contextlib
from importlib import resources
from pathlib import Path

__all__ = ["DEFAULT_PARAMETER_FILE_NAME", "shipped_file", "shipped_files", "default_parameter_file"]

DEFAULT_PARAMETER_FILE_NAME = "reference_wire.toml"
FOLDERS = {  # name -> (package, folder inside it)
    "models": ("sma_fmu", "models"),
    "scenarios": ("sma_fmu", "scenarios"),
    "examples": ("sma_fmu", "examples"),
}

_kept = contextlib.ExitStack()   # real-file copies (zip installs) live as long as the process
atexit.register(_kept.close)


def _folder(name):
    if name not in FOLDERS:
        raise ValueError(f"unknown data folder {name!r}; expected one of {', '.join(FOLDERS)}")
    package, folder = FOLDERS[name]
    return resources.files(package).joinpath(folder)


def shipped_files(name, suffix=""):
    """Names of the files in the shipped folder ``name`` ending in ``suffix``, sorted."""
    return sorted(entry.name for entry in _folder(name).iterdir()
                  if entry.is_file() and entry.name.endswith(suffix))


def shipped_file(name, file_name):
    """A real filesystem path of ``file_name`` in the shipped folder ``name``.

    Raises ``FileNotFoundError`` naming the folder when the file is not shipped.
    """
    resource = _folder(name).joinpath(file_name)
    if not resource.is_file():
        raise FileNotFoundError(f"{file_name!r} is not one of the shipped {name} "
                                f"({', '.join(shipped_files(name)) or 'none'})")
    return Path(_kept.enter_context(resources.as_file(resource)))


def default_parameter_file():
    """The reference wire's parameter file (a real path)."""
    return shipped_file("models", DEFAULT_PARAMETER_FILE_NAME)
