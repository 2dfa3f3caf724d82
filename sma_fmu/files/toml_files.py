"""Read a TOML file with one clear error for every way it can be unusable.

Missing, a folder, unreadable, not UTF-8 (latin-1, UTF-16), not TOML, or nested too
deeply: each raises the caller's error class with the file name and the reason. A UTF-8
byte-order mark is accepted.
"""
import tomllib
from pathlib import Path

__all__ = ["read_toml"]


def read_toml(path, error_class, what="file"):
    """Parse the TOML file ``path``; problems raise ``error_class`` naming the file.

    ``what`` names the kind of file in messages ("parameter file", "scenario file", ...).
    """
    path = Path(path)
    if path.is_dir():
        raise error_class(f"{path}: is a folder, not a {what}")
    try:
        data = path.read_bytes()
    except FileNotFoundError:
        raise error_class(f"{path}: {what} not found") from None
    except OSError as error:
        raise error_class(f"{path}: cannot read the {what}: {error.strerror or error}") from None
    try:
        text = data.decode("utf-8").removeprefix("\ufeff")
    except UnicodeDecodeError as error:
        raise error_class(f"{path}: not a UTF-8 text file (byte {error.start}: {error.reason}); "
                          f"save the {what} as UTF-8") from None
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as error:
        raise error_class(f"{path}: not valid TOML: {error}") from None
    except RecursionError:
        raise error_class(f"{path}: not valid TOML: nested too deeply") from None
