"""Prebuilt C-family binaries, shipped in the wheel: ``sma-fmu build --native`` without a compiler.

A C-family binary depends only on the model's ``sources/`` (the layer, the runtime, the
adapter, the generated ``<Model>_variables.h``, which holds the structure and the GUID
but no parameter file's values: :mod:`.c_family_description`, and the generated wire
parameter table: :mod:`.parameter_table`), so one binary per model and
platform serves every build. They live in ``sma_fmu/fmi/packaging/prebuilt_binaries/``
(package data of the wheel, not of the sdist, which builds from source; never committed) with ``manifest.json``: for each model, the SHA-256 of the
sources they were compiled from, and the file of each FMI 2.0 platform; under
:func:`fmi3_key` the same for the FMI 3.0 build (other sources: its front), per FMI 3.0
platform tuple.

:func:`find_prebuilt` gives a binary only when its sources' digest equals that of the
sources being packed, so a changed C file, another version (the GUID) or a stale folder is
never used: the build compiles instead. The Python family's C front is kept there too
(``front/linux64/front.so``, ``front/win64/front.dll``), taken only where no compiler
builds it; the prebuilt linux64 front records no build libpython. ``python -m sma_fmu.fmi.packaging.prebuilt_writer``
fills the folder; the build backend (``build_backend/wheel_backend.py``) runs it when it
builds the wheel, where gcc, mingw-w64 and zig are, and removes the folder after.
"""
import hashlib
import json
from pathlib import Path

__all__ = ["PREBUILT", "MANIFEST", "FRONTS", "sources_digest", "fmi3_key", "find_prebuilt",
           "find_prebuilt_front"]

PREBUILT = Path(__file__).parent / "prebuilt_binaries"
MANIFEST = "manifest.json"


def sources_digest(files):
    """SHA-256 (hex) of ``files``: {name: bytes} of a model's sources/ (names sorted)."""
    digest = hashlib.sha256()
    for name in sorted(files):
        digest.update(name.encode("utf-8") + b"\0" + hashlib.sha256(files[name]).digest())
    return digest.hexdigest()


def _manifest(folder):
    try:
        return json.loads((Path(folder) / MANIFEST).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return {}


def fmi3_key(model):
    """Where ``model``'s FMI 3.0 binaries are kept: its manifest key and folder name."""
    return f"{model}.fmi3"


def find_prebuilt(model, platform, digest, folder=None):
    """The bytes of ``model``'s prebuilt binary for ``platform`` (an FMI 2.0 folder name; an
    FMI 3.0 tuple under :func:`fmi3_key`), compiled from sources of ``digest``; None if
    there is none. ``folder``: default :data:`PREBUILT`."""
    folder = PREBUILT if folder is None else folder
    entry = _manifest(folder).get(model, {})
    name = entry.get("binaries", {}).get(platform)
    if entry.get("sources") != digest or not name:
        return None
    path = Path(folder) / model / platform / name
    return path.read_bytes() if path.is_file() else None


FRONTS = {"linux64": "front.so", "win64": "front.dll"}  # the Python family's, under front/


def find_prebuilt_front(platform, digest, folder=None):
    """The bytes of the Python family's prebuilt front for ``platform`` (linux64 or win64),
    compiled from front sources of ``digest`` and recording no build libpython; or None."""
    return find_prebuilt("front", platform, digest, folder)
