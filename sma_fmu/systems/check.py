"""Compliance checks of FMUs, SSP packages and container FMUs (``sma-fmu check``).

Per FMU (a container is an FMU; the FMUs inside an SSP are checked one by one):
- ``fmpy validation``: fmpy's check of modelDescription.xml (schema and rules);
- ``FMI checker``: fmu-manipulation-toolbox's checkers (FMI XSD and the standard's rules);
- ``C host (libcosim)``: a short run in sma-fmu's C host (:mod:`.c_host`), all outputs finite
  ("n/a" for an FMI 3.0 FMU: libcosim runs none);
- ``state round trip``: save the state, step, restore, step again: the same outputs, bit
  for bit (serialized and read back when the FMU can); "n/a" when it does not declare it;
  an FMI 3.0 FMU through fmpy's FMU3Slave.
- ``default experiment``: the FMU's default experiment run again in fmpy gives the
  reference result it carries (:mod:`sma_fmu.fmi.packaging.reference_results`, the fmi-ls-ref layout);
  "n/a" without one, or for an FMU an export packed with a scenario's values.
- ``wire``: the digest of the wire the FMU was built from, as its model description states
  it (the String constant ``wire_digest``) and as its resources hold it (parameters.json's
  values; a C-family FMU's model_starts.json too): FAIL where they differ, "n/a" for an FMU
  without a wire (a container).
Per SSP also ``SSD schema``: SystemStructure.ssd against the SSP 1.0 schemas (fmpy's
copy); ``packed defaults``: the FMUs' packed start values agree with their model
descriptions and the SSD's bindings; one ``host ...`` line per known host
(:mod:`.host_needs`: libcosim, Ecos, OMSimulator, fmpy's ``simulate_ssp``): what it needs
and applies, failing where it would run something other than what the SSD binds (a
binding it does not apply whose value the FMU's default does not hold, a missing
annotation, a name that is no identifier) or would log an error line (OMSimulator: a
String binding); and the C-host run is of the whole system,
with its parameter bindings.
Before any of these, ``archive``: the archive's entries (:mod:`sma_fmu.files.archives`:
no path leaving the tree, no link, no duplicate, no bomb, nested FMUs too); an unsafe
archive gets one FAIL line per unsafe entry and no other check.
Each check gives a :class:`CheckResult`; an exception inside a check is its failure.
"""
import functools
import logging
import math
import tempfile
import zipfile
from dataclasses import dataclass
from pathlib import Path

from sma_fmu.files.archives import inspect_archive
from sma_fmu.fmi.packaging.reference_results import reference_check
from sma_fmu.fmi.python_family.slave_support.wire_use import WIRE_DIGEST
from sma_fmu.systems.c_host import run_c_host
from sma_fmu.systems.host_needs import KNOWN_HOSTS, host_check, packed_defaults_check, read_ssp
from sma_fmu.systems.packed import START_VALUES_ENTRY
from sma_fmu.systems.ssp import NAMESPACES, SSD_NAME
from sma_fmu.systems.toolbox_log import toolbox_messages

__all__ = ["CheckResult", "SHORT_RUN_STEPS", "archive_results", "check_file", "check_files",
           "format_result"]

SHORT_RUN_STEPS = 100   # steps of the C-host run
_MODEL_STARTS = "resources/model_starts.json"   # a C-family FMU's build starts
STATE_STEPS = 20        # steps before and after saving the state
_DEFAULT_STEP_S = 1e-3  # when the file names no step size


@dataclass(frozen=True)
class CheckResult:
    """One line of the report: ``status`` "ok", "FAIL" or "n/a"."""

    file: str
    check: str
    status: str
    detail: str


def format_result(result):
    """``STATUS  FILE: CHECK: DETAIL`` (one line)."""
    detail = " ".join(result.detail.split())
    return f"{result.status:<5} {result.file}: {result.check}: {detail}"


def _run(file, check, function):
    try:
        status, detail = function()
    except Exception as error:  # noqa: BLE001 - a check that raises has failed
        status, detail = "FAIL", f"{type(error).__name__}: {error}"
    return CheckResult(str(file), check, status, detail)


def _fmpy_validation(path):
    from sma_fmu.fmi.packaging.build import validate_fmus

    problems = validate_fmus([path])[Path(path)]
    return ("ok", "no problems") if not problems else ("FAIL", "; ".join(problems))


def _toolbox_checker(path):
    from fmu_manipulation_toolbox.checker import get_checkers
    from fmu_manipulation_toolbox.operations import FMU

    with toolbox_messages(logging.ERROR) as errors, FMU(str(path)) as fmu:
        for checker in get_checkers():
            fmu.apply_operation(checker())
    return ("ok", "compliant") if not errors else ("FAIL", "; ".join(errors))


def _fmu_step(description):
    """The step size [s] of the FMU's default experiment (``description``: fmpy's)."""
    experiment = description.defaultExperiment
    step = experiment.stepSize if experiment is not None and experiment.stepSize else None
    return float(step) if step else _DEFAULT_STEP_S


def _short_run(kind, path, step_size):
    values = run_c_host(kind, path, step_size, SHORT_RUN_STEPS)
    if not values:
        return "FAIL", "the host reported no outputs"
    bad = [f"{name} = {value!r}" for name, value in values.items() if not math.isfinite(value)]
    if bad:
        return "FAIL", f"non-finite outputs after {SHORT_RUN_STEPS} steps: {', '.join(bad)}"
    return "ok", f"{SHORT_RUN_STEPS} steps of {step_size:g} s, {len(values)} outputs finite"


def _state_round_trip(path, description):
    from sma_fmu.fmi.driving.instance import FmuInstance

    cs = description.coSimulation
    if cs is None or not cs.canGetAndSetFMUstate:
        return "n/a", "the FMU does not declare canGetAndSetFMUstate"
    if description.fmiVersion.startswith("3"):
        return _state_round_trip3(path, description)
    step = _fmu_step(description)
    outputs = tuple(v.name for v in description.modelVariables
                    if v.type == "Real" and v.causality == "output")
    with FmuInstance(path, "state_check") as fmu:
        def run(first):
            values = []
            for k in range(first, first + STATE_STEPS):
                fmu.step(k * step, step)
                values.append(repr(fmu.get_real(outputs)))
            return values

        run(0)
        state = fmu.get_state()
        if cs.canSerializeFMUstate:
            saved, state = state, fmu.deserialize_state(fmu.serialize_state(state))
            fmu.free_state(saved)
        before = run(STATE_STEPS)
        fmu.set_state(state)
        after = run(STATE_STEPS)
        fmu.free_state(state)
    how = "serialized, " if cs.canSerializeFMUstate else ""
    return (("ok", f"{how}{STATE_STEPS} steps repeated bit for bit") if before == after
            else ("FAIL", f"{STATE_STEPS} steps after restoring the state differ from the first run"))


def _state_round_trip3(path, description):
    """The same round trip for an FMI 3.0 FMU, through fmpy's FMU3Slave (Float64 outputs,
    the plant's reversal arrays whole: nValues counts their elements)."""
    import math
    import shutil

    from fmpy import extract
    from fmpy.fmi3 import FMU3Slave

    cs, step = description.coSimulation, _fmu_step(description)
    floats = [v for v in description.modelVariables
              if v.type == "Float64" and v.causality == "output"]
    outputs = [v.valueReference for v in floats]
    count = sum(math.prod(v.shape) for v in floats)  # a scalar's shape is (): 1
    folder = extract(str(path))
    fmu = FMU3Slave(guid=description.instantiationToken, unzipDirectory=folder,
                    modelIdentifier=cs.modelIdentifier, instanceName="state_check")
    try:
        fmu.instantiate(logMessage=lambda *message: None)
        fmu.enterInitializationMode(startTime=0.0)
        fmu.exitInitializationMode()

        def run(first):
            values = []
            for k in range(first, first + STATE_STEPS):
                fmu.doStep(k * step, step)
                values.append(repr(fmu.getFloat64(outputs, nValues=count)))
            return values

        run(0)
        state = fmu.getFMUState()
        if cs.canSerializeFMUstate:
            saved, state = state, fmu.deserializeFMUState(fmu.serializeFMUState(state))
            fmu.freeFMUState(saved)
        before = run(STATE_STEPS)
        fmu.setFMUState(state)
        after = run(STATE_STEPS)
        fmu.freeFMUState(state)
        fmu.terminate()
    finally:
        fmu.freeInstance()
        shutil.rmtree(folder, ignore_errors=True)
    how = "FMI 3.0, serialized, " if cs.canSerializeFMUstate else "FMI 3.0, "
    return (("ok", f"{how}{STATE_STEPS} steps repeated bit for bit") if before == after
            else ("FAIL", f"{STATE_STEPS} steps after restoring the state differ from the first run"))


def _wire(path, description):
    """The FMU's wire digest, stated by its model description and held by its resources."""
    import json

    from sma_fmu.fmi.loop.wire_values import built_wire

    stated = next((v.start for v in description.modelVariables if v.name == WIRE_DIGEST), None)
    built = built_wire(path)
    with zipfile.ZipFile(path) as archive:
        starts = json.loads(archive.read(_MODEL_STARTS)) if _MODEL_STARTS in archive.namelist() \
            else {}
    if stated is None and built.params is None:
        return "n/a", "the FMU states no wire and holds no resources/parameters.json"
    held = {"resources/parameters.json": built.digest}
    if "wire_digest" in starts:
        held[_MODEL_STARTS] = starts["wire_digest"]
    if stated is not None:
        held["modelDescription.xml"] = stated
    if len(set(held.values())) != 1:
        return "FAIL", "; ".join(f"{where} says {digest}" for where, digest in held.items())
    how = "" if stated is not None else " (the model description states none: an older build)"
    return "ok", f"{built.digest} of {built.source}{how}"


def _c_host_run(path, description):
    """The C host's short run; n/a for FMI 3.0 (libcosim runs FMI 1.0 and 2.0 only)."""
    if description.fmiVersion.startswith("3"):
        return "n/a", "libcosim runs no FMI 3.0 FMU"
    return _short_run("fmu", path, _fmu_step(description))


def _fmu_checks(path, label, c_host=True):
    from fmpy import read_model_description

    # read once for the checks that need it; a failure to read fails each of them, as it
    # would have alone (exceptions are not cached)
    description = functools.cache(lambda: read_model_description(str(path)))
    results = [_run(label, "fmpy validation", lambda: _fmpy_validation(path)),
               _run(label, "FMI checker", lambda: _toolbox_checker(path)),
               _run(label, "wire", lambda: _wire(path, description()))]
    if c_host:
        results.append(_run(label, "C host (libcosim)", lambda: _c_host_run(path, description())))
    results.append(_run(label, "state round trip", lambda: _state_round_trip(path, description())))
    results.append(_run(label, "default experiment", lambda: reference_check(path, START_VALUES_ENTRY)))
    return results


def _ssd_schema(path):
    from fmpy.ssp.ssd import read_ssd

    ssd = read_ssd(str(path))
    return "ok", f"SSP {ssd.version}, system {ssd.system.name!r}, schema valid"


def _ssp_step(path):
    import xml.etree.ElementTree as ET

    with zipfile.ZipFile(path) as archive:
        root = ET.fromstring(archive.read(SSD_NAME))
    algorithm = root.find(f".//{{{NAMESPACES['osp']}}}FixedStepAlgorithm")
    return float(algorithm.get("baseStepSize")) if algorithm is not None else _DEFAULT_STEP_S


def _host_results(path):
    """The ``packed defaults`` and ``host ...`` lines of an SSP."""
    try:
        contents = read_ssp(path)
    except Exception as error:  # noqa: BLE001 - an unreadable SSD fails these checks
        return [CheckResult(str(path), "hosts", "FAIL", f"{type(error).__name__}: {error}")]
    results = [_run(path, "packed defaults", lambda: packed_defaults_check(contents))]
    for host in KNOWN_HOSTS:
        results.append(_run(path, f"host {host.name}", lambda host=host: host_check(host, contents)))
    return results


def _ssp_checks(path):
    results = [_run(path, "SSD schema", lambda: _ssd_schema(path)), *_host_results(path),
               _run(path, "C host (libcosim)", lambda: _short_run("ssp", path, _ssp_step(path)))]
    with tempfile.TemporaryDirectory(prefix="sma_fmu_check_") as folder, \
            zipfile.ZipFile(path) as archive:
        for name in sorted(n for n in archive.namelist() if n.lower().endswith(".fmu")):
            fmu = Path(archive.extract(name, folder))
            results += _fmu_checks(fmu, f"{path}[{name}]", c_host=False)
    return results


def archive_results(path):
    """The FAIL results of a file no check should read (empty: the checks may): not a zip
    archive, an unsafe entry (no host, library or unpacking ever sees one), or no
    modelDescription.xml (an FMU) or SystemStructure.ssd (an SSP package)."""
    path = Path(path)
    if not zipfile.is_zipfile(path):
        return [CheckResult(str(path), "archive", "FAIL", "not a zip archive (an FMU or SSP is one)")]
    problems = inspect_archive(path)
    if problems:
        return [CheckResult(str(path), "archive", "FAIL", f"unsafe entry {problem.entry!r}: {problem.rule}")
                for problem in problems]
    ssp = path.suffix.lower() == ".ssp"
    description = "SystemStructure.ssd" if ssp else "modelDescription.xml"
    with zipfile.ZipFile(path) as archive:
        if description not in archive.namelist():
            return [CheckResult(str(path), "archive", "FAIL",
                                f"not {'an SSP package' if ssp else 'an FMU'}: no {description} "
                                "at the top of the archive")]
    return []


def check_file(path):
    """The :class:`CheckResult` list of one FMU, container FMU or SSP package."""
    path = Path(path)
    if not path.is_file():
        raise ValueError(f"{path}: no such file")
    unreadable = archive_results(path)
    if unreadable:
        return unreadable
    if path.suffix.lower() == ".ssp":
        return _ssp_checks(path)
    return _fmu_checks(path, str(path))


def check_files(paths, report=print):
    """Check every file, ``report`` each line as it comes; returns True when none failed."""
    missing = [str(path) for path in paths if not Path(path).is_file()]
    if missing:
        raise ValueError(f"{missing[0]}: no such file")
    passed = True
    for path in paths:
        for result in check_file(path):
            report(format_result(result))
            passed = passed and result.status != "FAIL"
    return passed
