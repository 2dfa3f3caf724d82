"""The FMI Cross-Check tree of built FMUs (``sma-fmu export cross-check``).

The FMI Cross-Check rules (modelica/fmi-cross-check, FMI-CROSS-CHECK-RULES.md, 9.1) ask an
exporting tool for at least three FMUs per platform and FMI variant, each in

    fmus/2.0/cs/<platform>/sma-fmu/<version>/<Model>/

with ``<Model>.fmu``, ``<Model>_ref.csv`` (the reference result, StartTime to StopTime),
``<Model>_in.csv`` (the inputs, linear in between; FMUs with inputs), ``<Model>_ref.opt``
(StartTime, StopTime, StepSize, RelTol, and here OutputIntervalLength), a ReadMe and the
license. The reference and the inputs are those the FMU carries (:mod:`.reference_results`),
checked first by running the default experiment again. ``<platform>`` is the one the
references were computed on (this machine's, in the rules' names: linux64, win64,
darwin64); an FMU without a binary for it is left out. :func:`export_cross_check` writes
the tree through a staging folder: a failure leaves ``out`` as it was.
"""
import zipfile
from pathlib import Path

from sma_fmu import __version__
from sma_fmu.files.output_folder import staged_folder
from sma_fmu.fmi.packaging.reference_results import (LS_REF_FOLDER, MANIFEST, read_manifest, output_stride,
                                       reference_check)

__all__ = ["TOOL", "MINIMUM_FMUS", "REL_TOL", "cross_check_platform", "model_folder",
           "export_cross_check"]

TOOL = "sma-fmu"
MINIMUM_FMUS = 3      # per platform and FMI variant (the rules, 9.1)
REL_TOL = 1e-4        # RelTol of _ref.opt: the comparison band's, the FMUs have no solver tolerance


def cross_check_platform():
    """This machine's platform in the rules' names ("linux64", "win64", "darwin64")."""
    from fmpy import platform

    return platform


def model_folder(out, platform, model):
    """``out/fmus/2.0/cs/<platform>/sma-fmu/<version>/<model>``."""
    return Path(out) / "fmus" / "2.0" / "cs" / platform / TOOL / __version__ / model


def _license_text():
    """The project's license: the installed distribution's (pyproject's license-files), else
    the LICENSE of the source tree the package runs from (an editable install)."""
    from importlib import metadata

    try:
        distribution = metadata.distribution("sma-fmu")
        for name in ("licenses/LICENSE", "LICENSE"):
            text = distribution.read_text(name)
            if text:
                return text
    except metadata.PackageNotFoundError:
        pass
    tree = Path(__file__).resolve().parents[3] / "LICENSE"  # sma_fmu/fmi/packaging/ -> the checkout
    if tree.is_file():
        return tree.read_text(encoding="utf-8")
    raise ValueError("sma-fmu's LICENSE is neither installed nor beside the package: the "
                     "cross-check tree needs it")


def _readme(model, description, experiment, has_inputs, stride):
    inputs = (f"- `{model}_in.csv`: the inputs, piecewise linear: interpolate linearly between "
              "the rows and hold the last row.\n" if has_inputs else "- no inputs.\n")
    return (f"# {model}\n\n{description.description or ''}\n\n"
            f"Exported by sma-fmu {__version__} (a shape-memory-alloy wire actuator, its "
            "feedforward compensator, controller and drive as FMI 2.0 co-simulation FMUs; "
            "pythonfmu with a native C front). The FMU's own documentation is "
            "`documentation/index.html` inside it.\n\n"
            "## The reference\n\n"
            f"The FMU's default experiment: {experiment.start!r} s to {experiment.stop!r} s in "
            f"communication steps of {experiment.step!r} s, run in fmpy's `simulate_fmu` "
            "(`sma-fmu build` computes it; `sma-fmu check` and this export run it again and "
            "compare, to 1e-9 relative). The FMU carries the same files in "
            f"`{LS_REF_FOLDER}/` (FMI-LS-REF).\n\n"
            f"- `{model}_ref.csv`: every output, once every {stride} steps "
            f"(OutputIntervalLength {stride * experiment.step!r} s), Booleans as 0/1;\n"
            + inputs +
            f"- `{model}_ref.opt`: StartTime, StopTime, StepSize (the communication step), "
            "RelTol, OutputIntervalLength.\n\n"
            "To reproduce with fmpy:\n\n```python\nimport numpy as np\nfrom fmpy import simulate_fmu\n"
            + (f"inputs = np.genfromtxt('{model}_in.csv', delimiter=',', names=True)\n"
               if has_inputs else "inputs = None\n")
            + f"result = simulate_fmu('{model}.fmu', start_time={experiment.start!r}, "
              f"stop_time={experiment.stop!r}, output_interval={experiment.step!r}, input=inputs)\n```\n\n"
            "The FMU needs a CPython 3.10 or newer on the machine (see documentation/index.html, "
            "Platforms). No license check. License: see LICENSE.txt.\n")


def _entries(fmu_path, platform):
    """{file name: bytes} of one model folder, or (None, why) when the FMU is left out."""
    from fmpy import read_model_description

    with zipfile.ZipFile(fmu_path) as archive:
        names = set(archive.namelist())
        if MANIFEST not in names:
            return None, f"no {MANIFEST} (not built by sma-fmu build)"
        if not any(name.startswith(f"binaries/{platform}/") for name in names):
            return None, f"no binaries/{platform}/"
        experiment, stimuli_file, reference_file = read_manifest(archive)
        reference = archive.read(reference_file)
        stimuli = archive.read(stimuli_file) if stimuli_file else None
    status, detail = reference_check(fmu_path)
    if status != "ok":
        raise ValueError(f"{fmu_path}: its reference does not reproduce: {detail}")
    description = read_model_description(str(fmu_path))
    model, stride = description.modelName, output_stride(experiment)
    options = (f"StartTime, {experiment.start!r}\nStopTime, {experiment.stop!r}\n"
               f"StepSize, {experiment.step!r}\nRelTol, {REL_TOL!r}\n"
               f"OutputIntervalLength, {stride * experiment.step!r}\n")
    entries = {f"{model}.fmu": Path(fmu_path).read_bytes(), f"{model}_ref.csv": reference,
               f"{model}_ref.opt": options.encode("ascii"),
               "ReadMe.md": _readme(model, description, experiment, stimuli is not None,
                                    stride).encode("utf-8"),
               "LICENSE.txt": _license_text().encode("utf-8")}
    if stimuli is not None:
        entries[f"{model}_in.csv"] = stimuli
    return model, entries


def export_cross_check(fmu_dir, out, report=print):
    """Write the cross-check tree of the FMUs in ``fmu_dir`` under ``out``; returns the model
    folders written. ``report`` gets one line per FMU left out. Fewer than
    :data:`MINIMUM_FMUS` usable FMUs raise ``ValueError`` (the rules ask for three)."""
    fmu_dir = Path(fmu_dir)
    if not fmu_dir.is_dir():
        raise ValueError(f"--fmus {fmu_dir}: no such folder")
    platform = cross_check_platform()
    models = {}
    for path in sorted(fmu_dir.glob("*.fmu")):
        model, entries = _entries(path, platform)
        if model is None:
            report(f"left out: {path}: {entries}")
        elif model in models:
            raise ValueError(f"--fmus {fmu_dir}: two FMUs of the model {model!r}")
        else:
            models[model] = entries
    if len(models) < MINIMUM_FMUS:
        raise ValueError(f"--fmus {fmu_dir}: {len(models)} FMU(s) with a reference result for "
                         f"{platform}; the FMI Cross-Check rules ask for at least {MINIMUM_FMUS}")
    with staged_folder(out) as stage:
        for model, entries in models.items():
            folder = model_folder(stage, platform, model)
            folder.mkdir(parents=True)
            for name, data in entries.items():
                (folder / name).write_bytes(data)
    return [model_folder(out, platform, model) for model in models]
