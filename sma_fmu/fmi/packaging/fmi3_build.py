"""``sma-fmu build --native --fmi 3``: the five C-family FMUs as FMI 3.0 co-simulation FMUs.

The same C models and core as the FMI 2.0 build (:mod:`.c_family_build`), under the FMI 3.0
front (``c_family/fmi3/``). Each FMU holds:

- ``modelDescription.xml`` (FMI 3.0, :mod:`.fmi3_description`): the native FMI 2.0
  description in FMI 3.0's terms (instantiation token, ``time``, Enumerations);
- ``extra/org.sma-fmu.platforms/platforms.xml``: the platforms and how each was tested,
  which ``sma-fmu check`` reads (not a top-level ``<Annotations>``: the FMI Library 3.0.4
  logs an error for that);
- ``sources/``: the C files, flat, the generated ``<Model>_variables.h`` (the same table as
  FMI 2.0) and ``fmi3_model.h``, and ``buildDescription.xml`` listing what a tool compiles;
- ``binaries/<tuple>/<Model>.<suffix>`` for every target of the cross-build table, built as
  the FMI 2.0 ones are: the wheel's prebuilt binary of the same sources (:mod:`.prebuilt`,
  under :func:`~.prebuilt.fmi3_key`), else compiled here (a target without its toolchain is
  left out, with a warning);
- ``resources/parameters.json``, as in FMI 2.0;
- ``extra/org.fmi-standard.fmi-ls-ref/`` (the manifest, stimuli and reference result of the
  default experiment, fmi-ls-ref's FMI 3 layout, which is FMI 2.0's) and ``documentation/``
  (index.html, result.png), as in FMI 2.0 (:func:`.extras.add_documentation_and_reference`):
  the reference result is this FMU's own, run in fmpy's FMI 3.0 simulation; it equals the FMI
  2.0 twin's byte for byte (tests/fmus/test_fmu_user_docs.py);
- the plant's ``terminalsAndIcons/terminalsAndIcons.xml`` (:mod:`.fmi3_terminals`).
"""
import shutil
import warnings
import zipfile
from pathlib import Path

from sma_fmu.fmi.packaging.c_family_build import (NATIVE_MARKER, NativeBuildWarning,
                                                  build_from_twins, c_source_files, compile_binary,
                                                  exact_starts, model_sources)
from sma_fmu.fmi.packaging.c_family_description import (model_starts, native_description,
                                                        variables_header)
from sma_fmu.fmi.packaging.cross_build import TARGETS
from sma_fmu.fmi.packaging.extras import add_documentation_and_reference
from sma_fmu.fmi.packaging.fmi3_description import (build_description,
                                                    fmi3_description, fmi3_model_header,
                                                    platforms_document)
from sma_fmu.fmi.packaging.fmi3_terminals import terminals_and_icons
from sma_fmu.fmi.packaging.platforms import PLATFORMS_FILE
from sma_fmu.fmi.packaging.prebuilt import find_prebuilt, fmi3_key, sources_digest
from sma_fmu.fmi.packaging.reproducible import fix_timestamps

__all__ = ["PLATFORMS", "build_fmi3_fmus"]

# FMI 3.0 platform tuple -> (its compile target, the binary's suffix): every target of
# cross_build's table (gcc, mingw-w64, zig cc; one without its toolchain is left out, warned)
PLATFORMS = {name: (name, entry.suffix) for name, entry in TARGETS.items()}
_GENERATED = "fmi3_model.h"


def _build_one(model_name, python_fmu, folder, work, compile=False, step=None):
    """Write ``folder/<model_name>.fmu`` from the pythonfmu FMU; returns [problem texts]."""
    unpacked = work / model_name
    with zipfile.ZipFile(python_fmu) as archive:
        archive.extractall(unpacked)
    starts, defaults = exact_starts(model_name, unpacked / "resources")
    header_name = f"{model_name}_variables.h"
    names = model_sources(model_name, generated=(header_name, _GENERATED), front="fmi3")
    fmi2_description, _ = native_description((unpacked / "modelDescription.xml").read_bytes(),
                                             starts, [])
    description = fmi3_description(fmi2_description)
    sources = work / f"{model_name}.sources"
    sources.mkdir()
    files = c_source_files()
    for name in names:
        if name not in (header_name, _GENERATED):
            shutil.copyfile(files[name], sources / name)
    (sources / header_name).write_text(variables_header(fmi2_description), encoding="utf-8")
    (sources / _GENERATED).write_text(fmi3_model_header(description), encoding="utf-8")
    build_xml = build_description(model_name, [n for n in names if n.endswith(".c")])
    digest = sources_digest({**{path.name: path.read_bytes() for path in sources.iterdir()},
                             "buildDescription.xml": build_xml})
    binaries, problems = {}, []
    for platform, (target, suffix) in PLATFORMS.items():
        data = None if compile else find_prebuilt(fmi3_key(model_name), platform, digest)
        if step is not None:
            step(f"{model_name} {platform}{' (prebuilt)' if data is not None else ''}")
        if data is None:
            output = work / platform / f"{model_name}{suffix}"
            output.parent.mkdir(exist_ok=True)
            problem = compile_binary(target, sources, output)
            if problem:
                problems.append(f"{model_name}: built without {platform}: {problem}")
                continue
            data = output.read_bytes()
        binaries[f"binaries/{platform}/{model_name}{suffix}"] = data
        if NATIVE_MARKER not in data:
            raise RuntimeError(f"{platform}: the native marker is missing (layer_calls.c)")
    _require_this_machine(model_name, binaries, problems)
    fmu = folder / f"{model_name}.fmu"
    with zipfile.ZipFile(fmu, "w", zipfile.ZIP_DEFLATED) as archive:
        archive.writestr("modelDescription.xml", description)
        archive.writestr(PLATFORMS_FILE,
                         platforms_document({b.split("/")[1]: b for b in binaries}))
        terminals = terminals_and_icons(description)
        if terminals:
            archive.writestr("terminalsAndIcons/terminalsAndIcons.xml", terminals)
        for name in names:
            archive.write(sources / name, f"sources/{name}")
        archive.writestr("sources/buildDescription.xml", build_xml)
        for binary, data in binaries.items():
            archive.writestr(binary, data)
        archive.write(unpacked / "resources" / "parameters.json", "resources/parameters.json")
        # the start of every variable and the build's wire parameters: one binary serves
        # every parameter file, as in the FMI 2.0 build
        archive.writestr("resources/model_starts.json",
                         model_starts(fmi2_description, starts, defaults))
    # the default experiment run by this FMU: extra/ (fmi-ls-ref) and documentation/ (extras.py)
    add_documentation_and_reference(fmu)
    fix_timestamps(fmu)  # reproducible.py: the same inputs, the same bytes
    return problems


def _require_this_machine(model_name, binaries, problems):
    """Raise ValueError naming the missing compiler when no binary runs on this machine: the
    build runs each FMU for its reference result and documentation."""
    from fmpy import platform_tuple

    if any(binary.split("/")[1] == platform_tuple for binary in binaries):
        return
    why = next((problem.split(": ", 2)[-1] for problem in problems
                if f"without {platform_tuple}:" in problem),
               f"the C family has no target {platform_tuple}")
    raise ValueError(f"build --native --fmi 3: no binary of {model_name} for this machine "
                     f"({platform_tuple}), which the build runs for each FMU's reference result: "
                     f"{why}. The installed wheel carries them prebuilt; from a clone (an "
                     f"editable install), install a C compiler or zig (pip install ziglang)")


def build_fmi3_fmus(out_dir, parameter_file=None, names=None, compile=False):
    """Build the FMI 3.0 C-family FMUs (default: all five) into ``out_dir``; {name: path}.

    Each platform's binary is the wheel's prebuilt one when it was compiled from the same
    sources (:mod:`.prebuilt`), else, or with ``compile``, compiled here.
    Built beside ``out_dir`` and moved there at the end: a failed build leaves it as it was.
    """
    names, problems = build_from_twins(
        out_dir, parameter_file, names,
        lambda name, twin, folder, work, step: _build_one(name, twin, folder, work, compile, step),
        len(PLATFORMS), "native FMUs (FMI 3.0)")
    for message in problems:
        warnings.warn(NativeBuildWarning(f"FMI 3.0 FMUs {message}."), stacklevel=2)
    return {name: Path(out_dir) / f"{name}.fmu" for name in names}
