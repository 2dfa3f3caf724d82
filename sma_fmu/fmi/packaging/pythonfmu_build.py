"""Build the Python family's FMUs with pythonfmu (:func:`build_pythonfmu_fmus`).

Each FMU ships, in resources/:
- its slave script from its folder ``sma_fmu/fmi/models/<Model>/`` (named by its declaration,
  :mod:`sma_fmu.fmi.models`), renamed ``<script>_<stamp>``;
- a copy of ``sma_fmu/runtime`` (the physics, standard library only) renamed
  ``<script>_rt_<stamp>``, and a copy of ``sma_fmu/fmi/python_family/slave_support`` (the FMI glue, which
  needs pythonfmu) renamed ``<script>_fmi_<stamp>``, with their imports rewritten to match;
- ``parameters.json``: the wire parameter file used at build time;
- an FMU whose declaration names ``default_signals`` (SmaScenarioSignals): ``signals.json``,
  its default signals (those of that shipped scenario).

Its binaries are the C front (:mod:`sma_fmu.fmi.packaging.front_build`) for linux64 and win64,
in front of pythonfmu's; without a compiler for a platform the build warns
(:class:`~sma_fmu.fmi.packaging.front_build.FrontWarning`) and leaves win64 out, or keeps
pythonfmu's linux64 binary alone, saying so in the model description
(:mod:`sma_fmu.fmi.packaging.platforms`).

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
import sys
import tempfile
import warnings
from importlib import resources
from pathlib import Path

from sma_fmu import __version__
from sma_fmu.console import progress
from sma_fmu.fmi.packaging.extras import add_documentation_and_reference
from sma_fmu.fmi.models import declaration, declarations
from sma_fmu.fmi.packaging.fmu_names import DEFAULT_FMU_DIR
from sma_fmu.fmi.packaging.front_build import (FrontWarning, compile_fronts, install_fronts,
                                               stage_slave_module)
from sma_fmu.files.output_folder import staged_folder
from sma_fmu.fmi.packaging.reproducible import content_guid, fix_timestamps
from sma_fmu.files.package_data import shipped_file
from sma_fmu.files.toml_files import read_toml
from sma_fmu.runtime.signals import load_from_table, reference_from_table
from sma_fmu.wire.parameter_file import load_parameter_set

__all__ = ["code_stamp", "build_pythonfmu_fmus"]

# shipped package -> suffix of its renamed copy inside an FMU
_SHIPPED_PACKAGES = {"sma_fmu.runtime": "rt", "sma_fmu.fmi.python_family.slave_support": "fmi"}


def _package_sources(package):
    """{file name: bytes} of the Python modules of ``package`` (a shipped package)."""
    return {entry.name: entry.read_bytes() for entry in resources.files(package).iterdir()
            if entry.is_file() and entry.name.endswith(".py")}


def _shipped_sources():
    sources = [(f"{package}/{name}", data) for package in _SHIPPED_PACKAGES
               for name, data in sorted(_package_sources(package).items())]
    # each slave under the label it had when the scripts shared one folder: the same stamp
    sources += [(f"slaves/{declared.slave}", declared.slave_path.read_bytes())
                for declared in sorted(declarations(), key=lambda declared: declared.slave)]
    return sources


def code_stamp():
    """10-hex-digit hash of the package version and every shipped source file."""
    digest = hashlib.sha256(__version__.encode())
    for name, data in _shipped_sources():
        digest.update(name.encode())
        digest.update(data)
    return digest.hexdigest()[:10]


def _renamer(stem, stamp):
    """Function rewriting imports of the shipped packages to their renamed copies."""
    names = {package: f"{stem}_{suffix}_{stamp}" for package, suffix in _SHIPPED_PACKAGES.items()}
    pattern = re.compile("|".join(re.escape(p) + r"\b" for p in sorted(names, key=len, reverse=True)))
    return names, lambda text: pattern.sub(lambda match: names[match.group(0)], text)


def _default_signals(stage, scenario):
    """Write ``signals.json``, the signals of the shipped ``scenario``; returns [its path]."""
    # the shipped scenario's signal tables, read at the runtime's level (fmi is below cosim)
    document = read_toml(shipped_file("scenarios", f"{scenario}.toml"), ValueError, "scenario file")
    reference, load = reference_from_table(document["reference"]), load_from_table(document["load"])
    path = stage / "signals.json"
    path.write_text(json.dumps({"scenario": scenario, "reference": reference.as_table(),
                                "load": load.as_table()}, indent=2), encoding="utf-8")
    return [path]


def _stage(declared, stage, parameter_set, stamp):
    """Write the renamed packages, the rewritten slave script of the FMU ``declared`` and
    parameters.json into ``stage``."""
    script_name = declared.slave
    stem = Path(script_name).stem
    names, rename = _renamer(stem, stamp)
    project_files = []
    for package, renamed in names.items():
        folder = stage / renamed
        folder.mkdir()
        for name, data in _package_sources(package).items():
            (folder / name).write_text(rename(data.decode("utf-8")), encoding="utf-8")
        project_files.append(folder)
    source = declared.slave_path.read_text(encoding="utf-8")
    if "sma_fmu.runtime" not in source:
        raise ValueError(f"{script_name}: slave script does not import sma_fmu.runtime")
    staged_script = stage_slave_module(stage, f"{stem}_{stamp}", names["sma_fmu.fmi.python_family.slave_support"],
                                       stem, rename(source))
    document = parameter_set.as_json()
    document.update(source=str(parameter_set.path), sma_fmu_version=__version__, stamp=stamp)
    parameters = stage / "parameters.json"
    parameters.write_text(json.dumps(document, indent=2), encoding="utf-8")
    return staged_script, project_files + [parameters]


def _forget_staged_modules(stamp):
    """Drop modules imported from a staging folder, so a later load imports the FMU's own copy."""
    for name in [name for name in sys.modules if name.endswith(stamp) or f"_{stamp}." in name]:
        del sys.modules[name]


def _build_into(model_name, folder, parameter_set, stamp):
    """Build one FMU into ``folder`` (a staging folder); returns its path."""
    from pythonfmu.builder import FmuBuilder

    with tempfile.TemporaryDirectory(prefix="sma_fmu_stage_") as stage:
        declared = declaration(model_name)
        script, project_files = _stage(declared, Path(stage), parameter_set, stamp)
        if declared.default_signals:
            project_files += _default_signals(Path(stage), declared.default_signals)
        try:
            return Path(FmuBuilder.build_FMU(
                script, dest=folder / f"{model_name}.fmu", project_files=project_files,
                canGetAndSetFMUstate=True, canSerializeFMUstate=True))
        finally:
            _forget_staged_modules(stamp)
            if str(Path(stage)) in sys.path:  # pythonfmu leaves the script's folder on sys.path
                sys.path.remove(str(Path(stage)))


def build_pythonfmu_fmus(out_dir=DEFAULT_FMU_DIR, parameter_file=None, names=None,
                         label="pythonfmu FMUs"):
    """Build the Python family's FMUs (default: every registered one, :mod:`sma_fmu.fmi.models`)
    into ``out_dir``; return {name: path}. Built in a temporary folder beside ``out_dir`` and
    moved there at the end, so a failed build leaves ``out_dir`` as it was. A progress bar
    ``label`` counts the FMUs (:mod:`sma_fmu.console.progress`)."""
    names = [declared.name for declared in declarations()] if names is None else list(names)
    for name in names:
        declaration(name)   # ValueError for an unknown FMU, before anything is built
    parameter_set = load_parameter_set(parameter_file)
    stamp = code_stamp()
    with progress.bar(len(names) + 1, label, unit="step") as shown:   # the front, then each FMU
        shown.set_postfix_str("compiling the C front")
        fronts = compile_fronts()
        shown.update(1)
        with staged_folder(out_dir) as folder:
            for name in names:
                shown.set_postfix_str(name)
                path = _build_into(name, folder, parameter_set, stamp)
                fix_timestamps(path, content_guid(path))  # reproducible.py: no random GUID, no date
                install_fronts(path, name, fronts)
                add_documentation_and_reference(path)  # documentation/, extra/ fmi-ls-ref (extras.py)
                fix_timestamps(path)
                shown.update(1)
    for message in fronts.warnings():
        warnings.warn(FrontWarning(message), stacklevel=2)
    return {name: Path(out_dir) / f"{name}.fmu" for name in names}
