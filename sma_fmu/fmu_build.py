"""Build the SmaActuator and SmaFeedforward FMUs with pythonfmu, and validate FMUs with fmpy.

Each FMU ships, in resources/:
- its slave script from ``fmu_src/``, renamed ``<script>_<stamp>``;
- a copy of ``sma_fmu/runtime`` renamed ``<script>_rt_<stamp>``, the slave's imports
  rewritten to match;
- ``parameters.json``: the wire parameter file used at build time.

``<stamp>`` is a hash of all shipped code. pythonfmu FMUs loaded into one process share
``sys.modules``: with these names an FMU never runs another FMU type's modules, another
version's stale copy, or the ``sma_fmu`` installed in the host's environment. Instances
of one FMU built from the same code share modules of identical content; the slave
imports everything it needs when it loads, so a later instance unpacked elsewhere
finds nothing missing.
"""
import hashlib
import json
import re
import shutil
import sys
import tempfile
from pathlib import Path

from . import __version__
from .parameter_file import load_parameter_set
from .project_files import project_folder

__all__ = ["FMU_SCRIPTS", "DEFAULT_FMU_DIR", "code_stamp", "build_fmu", "build_fmus",
           "validate_fmus", "default_fmu_paths"]

FMU_SCRIPTS = {"SmaActuator": "sma_actuator.py", "SmaFeedforward": "sma_feedforward.py"}
DEFAULT_FMU_DIR = Path("fmus")
_RUNTIME_IMPORT = "sma_fmu.runtime"


def _runtime_dir():
    return Path(__file__).resolve().parent / "runtime"


def _shipped_sources():
    scripts = [project_folder("fmu_src") / name for name in FMU_SCRIPTS.values()]
    return sorted(_runtime_dir().glob("*.py")) + scripts


def code_stamp():
    """10-hex-digit hash of the package version and every shipped source file."""
    digest = hashlib.sha256(__version__.encode())
    for path in _shipped_sources():
        digest.update(path.name.encode())
        digest.update(path.read_bytes())
    return digest.hexdigest()[:10]


def _stage(script, stage, parameter_set, stamp):
    """Write the renamed runtime, the rewritten slave script and parameters.json into ``stage``."""
    package = f"{script.stem}_rt_{stamp}"
    shutil.copytree(_runtime_dir(), stage / package,
                    ignore=shutil.ignore_patterns("__pycache__", "*.pyc"))
    source = script.read_text(encoding="utf-8")
    if _RUNTIME_IMPORT not in source:
        raise ValueError(f"{script}: slave script does not import {_RUNTIME_IMPORT}")
    staged_script = stage / f"{script.stem}_{stamp}.py"
    staged_script.write_text(re.sub(re.escape(_RUNTIME_IMPORT) + r"\b", package, source),
                             encoding="utf-8")
    document = parameter_set.as_json()
    document.update(source=str(parameter_set.path), sma_fmu_version=__version__, stamp=stamp)
    parameters = stage / "parameters.json"
    parameters.write_text(json.dumps(document, indent=2), encoding="utf-8")
    return staged_script, [stage / package, parameters]


def _forget_staged_modules(stamp):
    """Drop modules imported from a staging folder, so a later load imports the FMU's own copy."""
    for name in [name for name in sys.modules if name.endswith(stamp) or f"_rt_{stamp}." in name]:
        del sys.modules[name]


def build_fmu(model_name, out_dir=DEFAULT_FMU_DIR, parameter_file=None):
    """Build one FMU (``"SmaActuator"`` or ``"SmaFeedforward"``) into ``out_dir``; return its path."""
    from pythonfmu.builder import FmuBuilder

    if model_name not in FMU_SCRIPTS:
        raise ValueError(f"unknown FMU {model_name!r}; expected one of {', '.join(FMU_SCRIPTS)}")
    parameter_set = load_parameter_set(parameter_file)
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    stamp = code_stamp()
    with tempfile.TemporaryDirectory(prefix="sma_fmu_stage_") as stage:
        script, project_files = _stage(project_folder("fmu_src") / FMU_SCRIPTS[model_name],
                                       Path(stage), parameter_set, stamp)
        try:
            return Path(FmuBuilder.build_FMU(
                script, dest=out_dir / f"{model_name}.fmu", project_files=project_files,
                canGetAndSetFMUstate=True, canSerializeFMUstate=True))
        finally:
            _forget_staged_modules(stamp)
            if str(Path(stage)) in sys.path:  # pythonfmu leaves the script's folder on sys.path
                sys.path.remove(str(Path(stage)))


def build_fmus(out_dir=DEFAULT_FMU_DIR, parameter_file=None):
    """Build both FMUs; return {model name: path}."""
    return {name: build_fmu(name, out_dir, parameter_file) for name in FMU_SCRIPTS}


def default_fmu_paths(out_dir=DEFAULT_FMU_DIR):
    """{model name: path} where :func:`build_fmus` puts the FMUs."""
    return {name: Path(out_dir) / f"{name}.fmu" for name in FMU_SCRIPTS}


def validate_fmus(paths):
    """fmpy's validation of each FMU: {path: list of problems} (empty list = valid)."""
    from fmpy.validation import validate_fmu

    results = {}
    for path in paths:
        path = Path(path)
        results[path] = ([f"{path}: no such file"] if not path.is_file()
                         else validate_fmu(str(path)))
    return results
