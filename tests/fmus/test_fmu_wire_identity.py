"""Where a build meets its data, its wire is checked: a saved state of another wire and a
resources folder of another build are refused by name (fmi2Error / fmi3Error, never
fatal), in both families and both FMI versions. The repros of the fuzz campaign: a state
saved by a build with R_P 30, a_h 75 restored into one built from the reference wire (the
C family took it without a word), and an FMU pointed at that build's resources folder (the
C family ran with its values while its own model description said 33 / 68)."""
import shutil
import zipfile
from ctypes import byref

import pytest
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave, defaultCallbacks, fmi2CallbackFunctions
from fmpy.fmi3 import FMU3Slave
from fmpy.logging import addLoggerProxy

from native_twins import LOGS, _LOGGER, Instance
from fmi3_twins import Instance3
from sma_fmu.fmi.packaging.build import build_fmus
from sma_fmu.wire.parameter_file import load_parameter_set, write_parameter_file
from system_needs import needs

FAMILIES = ["python", pytest.param("native", marks=needs("gcc")),
            pytest.param("fmi3", marks=needs("gcc"))]
SESSION = {"python": "fmus", "native": "native_fmus", "fmi3": "fmi3_fmus"}
MODEL = "SmaActuator"
ERROR = 3


@pytest.fixture(scope="module")
def other_wire(tmp_path_factory, parameter_set):
    """The campaign's other wire: R_P 30 ohm, a_h 75 degC (the reference: 33, 68)."""
    path = write_parameter_file(tmp_path_factory.mktemp("other") / "r30.toml",
                                parameter_set.params.replace(R_P=30.0, a_h=75.0), "r30", "",
                                parameter_set.meanings)
    return load_parameter_set(path)


@pytest.fixture(scope="module")
def built():
    """{family: SmaActuator built from the other wire}, each built once."""
    return {}


def _family(request, family, other_wire, tmp_path_factory):
    """(this session's FMU, the same model built from ``other_wire``) of ``family``."""
    own = request.getfixturevalue(SESSION[family])[MODEL]
    cache = request.getfixturevalue("built")
    if family not in cache:
        cache[family] = build_fmus(tmp_path_factory.mktemp(f"{family}-r30"), other_wire.path,
                                   [MODEL], native=family != "python",
                                   fmi_version=3 if family == "fmi3" else 2)[MODEL]
    return own, cache[family]


def _instance(family, path, name):
    return Instance3(path, name) if family == "fmi3" else Instance(path, name)


def _serialized(family, fmu):
    if family == "fmi3":
        return fmu.fmu.serializeFMUState(fmu.fmu.getFMUState())
    return fmu.fmu.serializeFMUstate(fmu.fmu.getFMUstate())


def _restore(family, fmu, blob):
    """The first status above OK of deserializing then setting ``blob``, and the last log line."""
    names = ("deserializeFMUState", "setFMUState") if family == "fmi3" else \
        ("deSerializeFMUstate", "setFMUstate")
    status, state = fmu.call(names[0], blob)
    if status == 0:
        status, _ = fmu.call(names[1], state)
    return status, fmu.log[-1][1] if fmu.log else ""


@pytest.mark.parametrize("family", FAMILIES)
def test_a_state_of_another_wire_is_refused_naming_both_digests(request, family, other_wire,
                                                                parameter_set, tmp_path_factory):
    own, other = _family(request, family, other_wire, tmp_path_factory)
    saver = _instance(family, other, f"{family}-saver")
    fmu = _instance(family, own, f"{family}-restorer")
    try:
        for instance in (saver, fmu):
            assert instance.start({"load": 0.05, "P_in": 2.0}) == 0
            assert instance.step(0.0, 0.5) == 0
        blob = _serialized(family, saver)
        before = fmu.values(["R", "T"])
        status, message = _restore(family, fmu, blob)
        assert status == ERROR, (status, message)
        sentence = (f"the state was saved by an FMU of another wire ({other_wire.digest}); this "
                    f"FMU's wire is {parameter_set.digest}: restore it into an FMU built from "
                    "the same parameter file")
        assert sentence in message, message
        assert fmu.values(["R", "T"]) == before and fmu.step(0.5, 0.5) == 0   # unchanged, alive
        status, _ = _restore(family, fmu, _serialized(family, fmu))           # its own: taken
        assert status == 0
    finally:
        saver.close()
        fmu.close()


def _instantiate_with(family, binary_fmu, resources_fmu, name):
    """Instantiate ``binary_fmu`` (its binary and model description's GUID) with the resources
    folder of ``resources_fmu`` unpacked elsewhere; (component or None, [(status, text)])."""
    description = read_model_description(str(binary_fmu))
    folder, elsewhere = extract(str(binary_fmu)), extract(str(resources_fmu))
    log = []
    try:
        if family == "fmi3":
            fmu = FMU3Slave(guid=description.instantiationToken, unzipDirectory=folder,
                            modelIdentifier=MODEL, instanceName=name)
            fmu.unzipDirectory = elsewhere   # what instantiate takes the resource path from
            try:
                fmu.instantiate(logMessage=lambda env, status, category, message:
                                log.append((status, message.decode())))
            except Exception:  # noqa: BLE001 - fmpy raises a bare Exception for NULL
                return None, log
            fmu.freeInstance()
            return True, log
        fmu = FMU2Slave(guid=description.guid, unzipDirectory=folder, modelIdentifier=MODEL,
                        instanceName=name)
        fmu.unzipDirectory = elsewhere
        callbacks = fmi2CallbackFunctions()
        callbacks.logger = _LOGGER
        callbacks.allocateMemory = defaultCallbacks.allocateMemory
        callbacks.freeMemory = defaultCallbacks.freeMemory
        addLoggerProxy(byref(callbacks))
        LOGS[name] = log
        try:
            fmu.instantiate(callbacks=callbacks)
        except Exception:  # noqa: BLE001
            return None, log
        fmu.freeInstance()
        return True, log
    finally:
        shutil.rmtree(folder, ignore_errors=True)
        shutil.rmtree(elsewhere, ignore_errors=True)


@pytest.mark.parametrize("family", FAMILIES)
def test_another_builds_resources_folder_is_refused_by_name(request, family, other_wire,
                                                            tmp_path_factory):
    own, other = _family(request, family, other_wire, tmp_path_factory)
    component, log = _instantiate_with(family, own, other, f"{family}-resources")
    assert component is None
    errors = [text for status, text in log if status == ERROR]
    assert errors and not [text for status, text in log if status == 4], log
    assert "does not match the guid" in errors[-1] or "does not match the instantiationToken" \
        in errors[-1], errors
    assert other_wire.digest in errors[-1] and "different builds" in errors[-1], errors
    # its own resources: taken
    assert _instantiate_with(family, own, own, f"{family}-own")[0] is True


@pytest.mark.parametrize("family", FAMILIES)
def test_the_digest_is_stated_and_read_back(request, family, parameter_set, other_wire,
                                            tmp_path_factory):
    own, other = _family(request, family, other_wire, tmp_path_factory)
    for path, wire in ((own, parameter_set), (other, other_wire)):
        fmu = _instance(family, path, f"{family}-digest-{wire.name}")
        try:
            assert fmu.start({}) == 0
            status, value = fmu.get("wire_digest")
            assert status == 0 and (value.decode() if isinstance(value, bytes) else value) == wire.digest
        finally:
            fmu.close()
    if family != "python":
        # one binary for every wire: the same bytes; the GUID/token differs with the wire
        with zipfile.ZipFile(own) as a, zipfile.ZipFile(other) as b:
            binaries = [n for n in a.namelist() if n.startswith("binaries/")]
            assert binaries and all(a.read(n) == b.read(n) for n in binaries)
        tokens = [read_model_description(str(p)) for p in (own, other)]
        assert len({d.guid if family == "native" else d.instantiationToken for d in tokens}) == 2


def test_the_page_names_the_wire_file_and_digest(request, other_wire, tmp_path_factory):
    import html
    import re

    _, other = _family(request, "python", other_wire, tmp_path_factory)
    with zipfile.ZipFile(other) as archive:
        page = archive.read("documentation/index.html").decode("utf-8")
    file = re.search(r'<code class="wire-file">([^<]*)</code>', page)
    digest = re.search(r'<code class="wire-digest">([^<]*)</code>', page)
    assert file and html.unescape(file.group(1)) == str(other_wire.path)
    assert digest and digest.group(1) == other_wire.digest
