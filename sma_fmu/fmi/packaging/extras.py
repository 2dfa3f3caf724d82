"""Post-process a built FMU archive: its documentation and its reference result.

:func:`add_documentation_and_reference` is called once per FMU by ``sma-fmu build`` (the
pythonfmu FMUs, :mod:`.build`) and by the FMI 3.0 C family (:mod:`.fmi3_build`, which runs the
FMI 3.0 FMU itself): it works on any FMI 2.0 or 3.0 co-simulation archive. It

1. gives the FMU a DefaultExperiment if it has none (:data:`DEFAULT_EXPERIMENT`);
2. runs that experiment in fmpy with the model's stimuli (:mod:`.reference_results`);
3. writes into the archive the fmi-ls-ref files (manifest, ``<Model>_in.csv``,
   ``<Model>_out.csv`` under ``extra/org.fmi-standard.fmi-ls-ref/``) and
   ``documentation/index.html`` with ``documentation/result.png`` (and, for the plant,
   ``documentation/hysteresis.png``: R over T) (:mod:`.documentation`).

:func:`add_documentation` does step 3's documentation only, from the reference result the
archive already carries: the FMI 2.0 C family's FMUs, whose ``extra/`` is their pythonfmu
twin's (the same numbers), so nothing but ``documentation/`` is added to them.

Entries it writes replace entries of the same name (running it twice gives the same
archive but for the figure's and the XML's bytes); the others are copied unchanged.
"""
import os
import shutil
import xml.etree.ElementTree as ET
import zipfile
from pathlib import Path

from sma_fmu.fmi.packaging.documentation import (FIGURE, HYSTERESIS, INDEX, figure_png, hysteresis_png,
                                                 index_html)
from sma_fmu.fmi.packaging.reference_results import (LS_REF_FOLDER, MANIFEST, Experiment, csv_bytes,
                                                     experiment_of, manifest_bytes, read_csv_bytes,
                                                     read_manifest, simulate_experiment, stimuli)

__all__ = ["DEFAULT_EXPERIMENT", "add_documentation_and_reference", "add_documentation"]

DEFAULT_EXPERIMENT = Experiment(0.0, 10.0, 1e-3)   # start, stop, step [s] for an FMU without one
_MODEL_DESCRIPTION = "modelDescription.xml"
_FILE_MODE = 0o644 << 16   # a regular file, rw-r--r--


def _with_experiment(text, experiment):
    """modelDescription.xml with a DefaultExperiment (before VendorAnnotations/ModelVariables)."""
    root = ET.fromstring(text)
    node = ET.Element("DefaultExperiment", startTime=repr(experiment.start),
                      stopTime=repr(experiment.stop), stepSize=repr(experiment.step))
    before = root.find("VendorAnnotations")
    if before is None:
        before = root.find("ModelVariables")
    root.insert(list(root).index(before), node)
    ET.indent(root, space="\t")
    return ET.tostring(root, encoding="UTF-8", xml_declaration=True)


def _rewrite(fmu_path, entries):
    """Replace or add ``entries`` ({name: bytes}) in the archive, through a temporary file."""
    fmu_path = Path(fmu_path)
    temporary = fmu_path.with_name(fmu_path.name + ".extras.tmp")
    try:
        with zipfile.ZipFile(fmu_path) as source, \
                zipfile.ZipFile(temporary, "w", zipfile.ZIP_DEFLATED) as target:
            for item in source.infolist():
                if item.filename not in entries:
                    target.writestr(item, source.read(item.filename), zipfile.ZIP_DEFLATED)
            for name, data in entries.items():
                info = zipfile.ZipInfo(name, (2026, 1, 1, 0, 0, 0))
                info.external_attr = _FILE_MODE
                target.writestr(info, data, zipfile.ZIP_DEFLATED)
        shutil.move(str(temporary), str(fmu_path))
    finally:
        if temporary.exists():
            os.unlink(temporary)


def add_documentation_and_reference(fmu_path):
    """Give the FMU ``fmu_path`` its default experiment's reference result (fmi-ls-ref) and
    ``documentation/index.html``, in place; returns {role: archive path} of what it wrote."""
    from fmpy import read_model_description

    fmu_path = Path(fmu_path)
    description = read_model_description(str(fmu_path))
    experiment = experiment_of(description)
    if experiment is None:
        with zipfile.ZipFile(fmu_path) as archive:
            text = archive.read(_MODEL_DESCRIPTION)
        _rewrite(fmu_path, {_MODEL_DESCRIPTION: _with_experiment(text, DEFAULT_EXPERIMENT)})
        description = read_model_description(str(fmu_path))
        experiment = experiment_of(description)
    name = description.modelName
    inputs = stimuli(description, experiment)
    result = simulate_experiment(fmu_path, description, experiment, inputs)
    files = {"manifest": MANIFEST, "result": f"{LS_REF_FOLDER}/{name}_out.csv"}
    entries = {MANIFEST: manifest_bytes(name, experiment, inputs is not None),
               files["result"]: csv_bytes(result)}
    if inputs is not None:
        files["stimuli"] = f"{LS_REF_FOLDER}/{name}_in.csv"
        entries[files["stimuli"]] = csv_bytes(inputs)
    _rewrite(fmu_path, entries)
    return _document(fmu_path, description, experiment, result, inputs, files)


def _document(fmu_path, description, experiment, result, inputs, files):
    """Write documentation/index.html and its figure of ``result`` into the FMU; ``files``
    updated with their names."""
    units = {v.name: v.unit for v in description.modelVariables}
    name = description.modelName
    figures = {FIGURE: figure_png(result, inputs, units, f"{name}: default experiment")}
    files = dict(files, figure=FIGURE)
    hysteresis = hysteresis_png(result, units, f"{name}: R over T in the default experiment")
    if hysteresis is not None:
        figures[HYSTERESIS], files["hysteresis"] = hysteresis, HYSTERESIS
    _rewrite(fmu_path, figures)     # index.html reads the platforms from the archive
    _rewrite(fmu_path, {INDEX: index_html(fmu_path, description, experiment, files).encode("utf-8")})
    return dict(files, index=INDEX)


def add_documentation(fmu_path):
    """Give the FMU ``fmu_path``, which carries its reference result (fmi-ls-ref), its
    ``documentation/``, in place; returns {role: archive path} of the reference files and
    what it wrote."""
    from fmpy import read_model_description

    fmu_path = Path(fmu_path)
    with zipfile.ZipFile(fmu_path) as archive:
        experiment, stimuli_file, result_file = read_manifest(archive)
        result = read_csv_bytes(archive.read(result_file))
        inputs = read_csv_bytes(archive.read(stimuli_file)) if stimuli_file else None
    files = {"manifest": MANIFEST, "result": result_file}
    if stimuli_file:
        files["stimuli"] = stimuli_file
    return _document(fmu_path, read_model_description(str(fmu_path)), experiment, result, inputs, files)
