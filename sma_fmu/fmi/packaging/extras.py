"""Post-process a built FMU archive: its documentation and its reference result.

:func:`add_documentation_and_reference` is called once per FMU by ``sma-fmu build`` (the
pythonfmu FMUs, :mod:`.build`) and by the native C family on its FMUs: it works on any FMI
2.0 co-simulation archive. It

1. gives the FMU a DefaultExperiment if it has none (:data:`DEFAULT_EXPERIMENT`);
2. runs that experiment in fmpy with the model's stimuli (:mod:`.reference_results`);
3. writes into the archive the fmi-ls-ref files (manifest, ``<Model>_in.csv``,
   ``<Model>_out.csv`` under ``extra/org.fmi-standard.fmi-ls-ref/``) and
   ``documentation/index.html`` with ``documentation/result.png`` (:mod:`.documentation`).

Entries it writes replace entries of the same name (running it twice gives the same
archive but for the figure's and the XML's bytes); the others are copied unchanged.
"""
import os
import shutil
import xml.etree.ElementTree as ET
import zipfile
from pathlib import Path

from sma_fmu.fmi.packaging.documentation import FIGURE, INDEX, figure_png, index_html
from sma_fmu.fmi.packaging.reference_results import (LS_REF_FOLDER, MANIFEST, Experiment, csv_bytes,
                                       experiment_of, manifest_bytes, simulate_experiment, stimuli)

__all__ = ["DEFAULT_EXPERIMENT", "add_documentation_and_reference"]

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
    units = {v.name: v.unit for v in description.modelVariables}
    entries[FIGURE] = figure_png(result, inputs, units, f"{name}: default experiment")
    _rewrite(fmu_path, entries)     # index.html reads the platforms from the archive
    _rewrite(fmu_path, {INDEX: index_html(fmu_path, description, experiment, files).encode("utf-8")})
    files.update(index=INDEX, figure=FIGURE)
    return files
