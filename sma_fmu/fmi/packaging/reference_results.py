"""An FMU's default experiment and its reference result, in the fmi-ls-ref layout.

Each built FMU carries, as the Reference-FMUs do (modelica/Reference-FMUs, layered standard
FMI-LS-REF, github.com/modelica/fmi-ls-ref):

    extra/org.fmi-standard.fmi-ls-ref/fmi-ls-manifest.xml   the manifest: one Experiment
    extra/org.fmi-standard.fmi-ls-ref/<Model>_in.csv        its stimuli (FMUs with inputs)
    extra/org.fmi-standard.fmi-ls-ref/<Model>_out.csv       its result

The experiment is the FMU's DefaultExperiment (start, stop, communication step). Its
stimuli (the ``[stimuli]`` of the FMU's declaration, ``fmi/models/<Model>/fmu.toml``) are
piecewise linear (a host interpolates linearly between the
rows, as the FMI Cross-Check rules ask); an input they do not name stays at its start
value. fmpy's ``simulate_fmu`` runs it, one communication step of ``stepSize`` at a time;
the result keeps every output, Booleans as 0/1, once every :func:`output_stride` steps
(at most :data:`MAX_ROWS` rows: each CSV stays under the rules' 1 MB).
:func:`reference_check` runs it again and compares (``sma-fmu check``).
"""
import io
import tempfile
import xml.etree.ElementTree as ET
import zipfile

import numpy as np

from sma_fmu.console.interrupts import deferred
from sma_fmu.fmi.models import REGISTRY, declaration
__all__ = ["LS_REF_FOLDER", "MANIFEST", "LS_REF_VERSION", "MAX_ROWS", "RTOL", "ATOL",
           "Experiment", "experiment_of", "stimuli", "output_stride", "simulate_experiment",
           "csv_bytes", "read_csv_bytes", "manifest_bytes", "read_manifest", "reference_check"]

LS_REF_FOLDER = "extra/org.fmi-standard.fmi-ls-ref"
MANIFEST = f"{LS_REF_FOLDER}/fmi-ls-manifest.xml"
LS_REF_VERSION = "1.0.0-rc.1"
_LS_NAMESPACE = "http://fmi-standard.org/fmi-ls-manifest"
_LS_DESCRIPTION = "Layered Standard providing reference stimuli and results for an FMU."
MAX_ROWS = 1501       # result rows at most (the stride grows to keep under it)
RTOL, ATOL = 1e-9, 1e-12   # reference_check's tolerance: |result - ref| <= ATOL + RTOL |ref|



class Experiment:
    """The default experiment of an FMU: ``start``, ``stop``, ``step`` [s]."""

    def __init__(self, start, stop, step):
        self.start, self.stop, self.step = float(start), float(stop), float(step)
        if not (self.stop > self.start and 0.0 < self.step <= self.stop - self.start):
            raise ValueError(f"DefaultExperiment startTime = {start!r} s, stopTime = {stop!r} s, "
                             f"stepSize = {step!r} s: need start < stop and 0 < step <= stop - start")

    @property
    def steps(self):
        """Communication steps from start to stop."""
        return int(round((self.stop - self.start) / self.step))


def experiment_of(description):
    """The :class:`Experiment` of fmpy's ``description``; None without a complete one."""
    experiment = description.defaultExperiment
    if experiment is None or None in (experiment.startTime, experiment.stopTime, experiment.stepSize):
        return None
    return Experiment(experiment.startTime, experiment.stopTime, experiment.stepSize)


def _inputs(description):
    return [v for v in description.modelVariables if v.causality == "input"]


def stimuli(description, experiment):
    """The stimuli of the FMU's model (its declaration's, :mod:`sma_fmu.fmi.models`; none for a
    model not registered) as a structured array with ``time`` first and one column per
    input, or None for an FMU without inputs. An input not in the table holds its start
    value."""
    inputs = _inputs(description)
    if not inputs:
        return None
    model = description.modelName
    table = declaration(model).stimuli if model in REGISTRY else {}
    unknown = sorted(set(table) - {v.name for v in inputs})
    if unknown:
        raise ValueError(f"{description.modelName}: the stimuli name {unknown[0]!r}, which is no input")
    times = sorted({experiment.start, experiment.stop}
                   | {t for rows in table.values() for t, _ in rows
                      if experiment.start <= t <= experiment.stop})
    columns = [("time", np.float64)] + [(v.name, np.float64) for v in inputs]
    array = np.zeros(len(times), dtype=columns)
    array["time"] = times
    for variable in inputs:
        rows = table.get(variable.name)
        if rows is None:
            array[variable.name] = float(variable.start or 0.0)
        else:
            array[variable.name] = np.interp(times, [t for t, _ in rows], [v for _, v in rows])
    return array


def output_stride(experiment):
    """Steps between result rows: the smallest prime giving at most MAX_ROWS rows (1 if
    every step fits). A prime does not alias with a periodic output (the PWM driver's 20
    steps per period, sampled every 20th step, would show one phase only)."""
    stride = 1
    while experiment.steps // stride + 1 > MAX_ROWS:
        stride += 1
        while any(stride % divisor == 0 for divisor in range(2, int(stride ** 0.5) + 1)):
            stride += 1
    return stride


def simulate_experiment(fmu_path, description, experiment, inputs, outputs=None):
    """Run the default experiment in fmpy's ``simulate_fmu``; ``outputs`` (default: every
    scalar output), once every stride step (rows from ``start``; Booleans as 0/1).

    The FMU is unpacked and instantiated here, not by ``simulate_fmu``, which on an error or
    a Ctrl-C would leave both behind (its unpacked folder, an instance never freed)."""
    from fmpy import extract, simulate_fmu
    from fmpy.simulation import instantiate_fmu

    if outputs is None:
        outputs = [v.name for v in description.modelVariables
                   if v.causality == "output" and not v.dimensions]
    with tempfile.TemporaryDirectory(prefix="sma_fmu_reference_") as folder:
        extract(str(fmu_path), folder)
        with deferred():   # made and held below, or not made
            fmu = instantiate_fmu(folder, description, "CoSimulation")
        try:
            result = simulate_fmu(folder, start_time=experiment.start, stop_time=experiment.stop,
                                  output_interval=experiment.step, input=inputs, output=outputs,
                                  validate=False, model_description=description, fmu_instance=fmu)
        finally:
            with deferred():
                fmu.freeInstance()
    result = result[::output_stride(experiment)]
    columns = [(name, np.float64) for name in result.dtype.names]
    plain = np.zeros(result.size, dtype=columns)
    for name in result.dtype.names:
        plain[name] = result[name].astype(np.float64)
    return plain


def csv_bytes(array):
    """The FMI Cross-Check CSV of a structured array: quoted names, then rows of numbers
    (``repr``, so a value reads back to the same float)."""
    names = array.dtype.names
    lines = [",".join(f'"{name}"' for name in names)]
    lines += [",".join(repr(float(value)) for value in row) for row in array.tolist()]
    return ("\n".join(lines) + "\n").encode("ascii")


def read_csv_bytes(data):
    """A structured array (float columns) of :func:`csv_bytes`' format."""
    return np.genfromtxt(io.BytesIO(data), delimiter=",", names=True, deletechars="",
                         dtype=np.float64)


def manifest_bytes(model_name, experiment, has_stimuli):
    """fmi-ls-manifest.xml: the default experiment with its stimuli and references, and the
    result as a Related file (the Reference-FMUs' alpha manifests list only that)."""
    ET.register_namespace("fmi-ls", _LS_NAMESPACE)
    root = ET.Element("fmiReferences", {f"{{{_LS_NAMESPACE}}}fmi-ls-name": "org.fmi-standard.fmi-ls-ref",
                                        f"{{{_LS_NAMESPACE}}}fmi-ls-version": LS_REF_VERSION,
                                        f"{{{_LS_NAMESPACE}}}fmi-ls-description": _LS_DESCRIPTION})
    node = ET.SubElement(root, "Experiment", name="default",
                         description="The DefaultExperiment of modelDescription.xml",
                         startTime=repr(experiment.start), stopTime=repr(experiment.stop),
                         stepSize=repr(experiment.step))
    if has_stimuli:
        ET.SubElement(node, "Stimuli", source=f"{model_name}_in.csv")
    ET.SubElement(node, "References", source=f"{model_name}_out.csv")
    ET.SubElement(root, "Related", type="text/csv", source=f"{model_name}_out.csv", role="result",
                  description="Output of the default experiment")
    ET.indent(root)
    return ET.tostring(root, encoding="UTF-8", xml_declaration=True)


def read_manifest(archive):
    """(Experiment, stimuli file or None, references file) of the manifest in ``archive``."""
    root = ET.fromstring(archive.read(MANIFEST))
    node = root.find("Experiment")
    if node is None or node.find("References") is None:
        raise ValueError(f"{MANIFEST}: no Experiment with References")
    experiment = Experiment(node.get("startTime"), node.get("stopTime"), node.get("stepSize"))
    stimuli_node = node.find("Stimuli")
    stimuli_file = None if stimuli_node is None else f"{LS_REF_FOLDER}/{stimuli_node.get('source')}"
    return experiment, stimuli_file, f"{LS_REF_FOLDER}/{node.find('References').get('source')}"


def reference_check(fmu_path, packed_entry=None):
    """(status, detail): does the default experiment, run again in fmpy, give the FMU's
    reference result (within RTOL, ATOL)? "n/a" without a manifest, or for an FMU packed
    with other defaults (``packed_entry``: the entry that marks one)."""
    from fmpy import read_model_description

    with zipfile.ZipFile(fmu_path) as archive:
        names = set(archive.namelist())
        if MANIFEST not in names:
            return "n/a", f"no {MANIFEST} (not built by sma-fmu build)"
        if packed_entry and packed_entry in names:
            return "n/a", ("packed with a scenario's values as defaults: its reference is of the "
                           "built FMU's defaults")
        experiment, stimuli_file, reference_file = read_manifest(archive)
        reference = read_csv_bytes(archive.read(reference_file))
        inputs = read_csv_bytes(archive.read(stimuli_file)) if stimuli_file else None
    description = read_model_description(str(fmu_path))
    # the reference's outputs (an FMI 3.0 FMU's is its FMI 2.0 twin's: no FMI 3.0 arrays)
    result = simulate_experiment(fmu_path, description, experiment, inputs,
                                 [name for name in reference.dtype.names if name != "time"])
    if result.size != reference.size or result.dtype.names != reference.dtype.names:
        return "FAIL", (f"the run gives {result.size} rows of {', '.join(result.dtype.names)}, "
                        f"the reference {reference.size} rows of {', '.join(reference.dtype.names)}")
    worst, where = 0.0, None
    for name in reference.dtype.names:
        excess = np.abs(result[name] - reference[name]) - (ATOL + RTOL * np.abs(reference[name]))
        row = int(np.argmax(excess))
        if excess[row] > 0.0 and (where is None or excess[row] > worst):
            worst, where = float(excess[row]), (name, row)
    if where is not None:
        name, row = where
        return "FAIL", (f"{name} at t = {float(reference['time'][row])!r} s is "
                        f"{float(result[name][row])!r}, the reference {float(reference[name][row])!r} (tolerance {RTOL:g} relative, {ATOL:g} "
                        "absolute)")
    return "ok", (f"{experiment.steps} steps of {experiment.step:g} s reproduce {reference.size} rows of "
                  f"{len(reference.dtype.names) - 1} output(s) (tolerance {RTOL:g} relative)")
