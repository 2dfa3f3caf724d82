"""C code both FMU families compile, and the FMI standard's headers, each kept once.

- ``file_uri.c`` (the resource-location URI), ``log_category.c`` (the log categories),
  ``state_frame.c`` (the saved-state frame with its CRC-32), with their headers;
- ``include/`` (:data:`FMI_HEADERS`): the FMI 2.0 and 3.0 headers as the standard publishes
  them (``fmi2Functions.h``, ``fmi2FunctionTypes.h``, ``fmi2TypesPlatform.h``,
  ``fmi3Functions.h``, ``fmi3FunctionTypes.h``, ``fmi3PlatformTypes.h``), as the
  Reference-FMUs' ``include/`` holds them: the one declaration of the FMI ABI. The C front,
  the C family, the C hosts and the bench's C FMU compile with it as an include path
  (:func:`include_flags`); a C-family FMU carries the headers its sources include in its
  ``sources/``, which a tool compiles on its own.
"""
from pathlib import Path

__all__ = ["C_COMMON", "FMI_HEADERS", "include_flags"]

C_COMMON = Path(__file__).parent
FMI_HEADERS = C_COMMON / "include"


def include_flags(*folders):
    """Compiler options (``-I`` folder, ...) for ``folders`` and then :data:`FMI_HEADERS`."""
    return [flag for folder in (*folders, FMI_HEADERS) for flag in ("-I", str(folder))]
