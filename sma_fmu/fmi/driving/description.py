"""Reading an FMU's model description with fmpy, with one named error for a file that is no FMU."""
from functools import lru_cache
from pathlib import Path

__all__ = ["FmuFileError", "read_description", "described"]


class FmuFileError(ValueError):
    """A file given as an FMU is missing, not a zip archive, or has no readable model description."""


def read_description(path):
    """fmpy's ModelDescription of the FMU ``path``; an unusable file raises :class:`FmuFileError`."""
    import zipfile

    from fmpy import read_model_description

    path = Path(path)
    if path.is_dir():
        raise FmuFileError(f"{path}: is a folder, not an FMU file")
    if not path.is_file():
        raise FmuFileError(f"{path}: FMU file not found")
    try:
        return read_model_description(str(path))
    except zipfile.BadZipFile:
        raise FmuFileError(f"{path}: not an FMU: not a zip archive (corrupt or truncated?)") from None
    except KeyError:
        raise FmuFileError(f"{path}: not an FMU: no modelDescription.xml in the archive") from None
    except Exception as error:  # fmpy raises bare Exceptions for XML problems
        raise FmuFileError(f"{path}: not a usable FMU: {error}") from None


@lru_cache(maxsize=64)
def described(version):
    """:func:`read_description` of the FMU file ``version`` (its resolved path, size and
    modification time [ns]), read once per file version and shared (read only): the loop's
    system and the unpacked FMU each read it, and a C master's start-up read every file twice."""
    return read_description(version[0])
