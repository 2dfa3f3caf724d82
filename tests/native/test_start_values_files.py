"""resources/start_values.json is read alike by both families (issue 38): the same documents
accepted, the same refused at fmi2Instantiate with the same message naming the file (and the
key, or the limit). Before, the C reader stopped at a NUL byte and took an encoded surrogate,
refused nesting, members and sizes that Python took, and Python raised RecursionError or
"int too large to convert to float"; a FIFO hung the C family's fmi2Instantiate forever."""
import os
import shutil
import subprocess
import sys
from ctypes import byref
from pathlib import Path

import pytest
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave, defaultCallbacks, fmi2CallbackFunctions

from native_twins import LOGS, _LOGGER
from fmpy.logging import addLoggerProxy

pytestmark = pytest.mark.needs("gcc")

MODEL = "SmaActuator"
VALID = b'{"source": "test", "values": {"T_start": 25.0}}'


def _members(count):
    return b'{"values": {' + b", ".join(b'"k%d": 1' % i for i in range(count)) + b"}}"


def _nested(depth):
    return b'{"values": {}, "x": ' + b"[" * (depth - 1) + b"]" * (depth - 1) + b"}"


DOCUMENTS = {
    "valid": VALID,
    "NUL and garbage after a valid document": VALID + b"\0garbage",
    "encoded surrogate": b'{"values": {"T_start": 1.0}, "s": "\xed\xa0\x80"}',
    "invalid UTF-8": b'{"values": {}, "s": "\xc3("}',
    "nesting 64 deep": _nested(64),
    "nesting 65 deep": _nested(65),
    "nesting 5000 deep": b"[" * 5000 + b"]" * 5000,
    "brackets inside a string": b'{"values": {}, "s": "' + b"[" * 100 + b'\\""}',
    "256 members": _members(256),
    "257 members": _members(257),
    "larger than 8 MiB": VALID + b" " * (8 << 20),
    "800-digit integer for a Real": b'{"values": {"T_start": ' + b"7" * 800 + b"}}",
    "5000-digit integer": b'{"values": {"T_start": ' + b"7" * 5000 + b"}}",
    "Real given as text": b'{"values": {"T_start": "25"}}',
    "syntax error": b'{"values": {"T_start": 25.0,}}',
    "UTF-8 BOM": b"\xef\xbb\xbf" + VALID,
}


def instantiate(fmu_path, name, prepare):
    """(instantiated, log texts with the resources folder as <resources>) of fmi2Instantiate
    after ``prepare(resources folder)``."""
    description = read_model_description(str(fmu_path))
    folder = extract(str(fmu_path))
    resources = Path(folder) / "resources"
    log = LOGS.setdefault(name, [])
    log.clear()
    try:
        prepare(resources)
        fmu = FMU2Slave(guid=description.guid, unzipDirectory=folder, instanceName=name,
                        modelIdentifier=description.coSimulation.modelIdentifier)
        callbacks = fmi2CallbackFunctions()
        callbacks.logger = _LOGGER
        callbacks.allocateMemory = defaultCallbacks.allocateMemory
        callbacks.freeMemory = defaultCallbacks.freeMemory
        addLoggerProxy(byref(callbacks))
        try:
            fmu.instantiate(callbacks=callbacks, loggingOn=False)
            made = True
            fmu.freeInstance()
        except Exception:  # noqa: BLE001 - fmpy's "Failed to instantiate model"
            made = False
        return made, [text.replace(str(resources), "<resources>") for status, text in log
                      if status >= 2]
    finally:
        shutil.rmtree(folder, ignore_errors=True)


def _writer(data):
    return lambda resources: (resources / "start_values.json").write_bytes(data)


@pytest.mark.parametrize("case", sorted(DOCUMENTS))
def test_both_families_accept_and_refuse_the_same_documents_alike(fmus, native_fmus, case):
    python = instantiate(fmus[MODEL], f"sv-py-{case}", _writer(DOCUMENTS[case]))
    native = instantiate(native_fmus[MODEL], f"sv-c-{case}", _writer(DOCUMENTS[case]))
    assert python[0] == native[0], (python, native)
    assert python[0] == (case in ("valid", "nesting 64 deep", "256 members",
                                  "brackets inside a string")), python
    if not native[0]:
        message = native[1][-1]
        assert "start_values.json" in message, message
        logged = "\n".join(python[1])  # pythonfmu logs the slave's ValueError, then the front
        assert "Traceback" not in logged and "RecursionError" not in logged
        if case == "syntax error" and sys.version_info >= (3, 13):
            # Python 3.13's json words a trailing comma its own way ("Illegal trailing comma
            # before end of object", a column earlier); the C reader words it as 3.11 and 3.12
            # do: both refuse the file, naming it, with the decoder's line and column
            assert "start_values.json: cannot be read (" in logged and "line 1 column" in logged
        else:
            assert message.split("start_values.json", 1)[1] in logged, (python, native)


LIMITS = {"nesting 65 deep": "nesting deeper than 64 levels", "257 members": "more than 256 members",
          "larger than 8 MiB": "larger than 8388608 bytes", "800-digit integer for a Real": "T_start = 777",
          "NUL and garbage after a valid document": f"a NUL byte at byte {len(VALID)}",
          "encoded surrogate": f"invalid UTF-8 at byte {DOCUMENTS['encoded surrogate'].index(0xED)}"}


@pytest.mark.parametrize("case", sorted(LIMITS))
def test_a_refusal_names_the_limit_or_key(native_fmus, case):
    made, log = instantiate(native_fmus[MODEL], f"limit-{case}", _writer(DOCUMENTS[case]))
    assert not made and LIMITS[case] in log[-1], log


def _special(kind):
    def prepare(resources):
        path = resources / "start_values.json"
        if kind == "fifo":
            os.mkfifo(path)
        elif kind == "folder":
            path.mkdir()
        else:
            path.symlink_to("/dev/zero")
    return prepare


def _child(fmu_path, kind):
    """In a child process (a hang is a timeout there, not a hung test run)."""
    made, log = instantiate(fmu_path, f"special-{kind}", _special(kind))
    print(made, " | ".join(log))


@pytest.mark.parametrize("kind", ["fifo", "folder", "dev-zero"])
def test_a_start_values_file_that_is_not_a_regular_file_is_refused_at_once(fmus, native_fmus, kind):
    for family, fmu in (("python", fmus[MODEL]), ("native", native_fmus[MODEL])):
        env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(Path(__file__).parents[1] / "support"),
                                                           os.environ.get("PYTHONPATH", "")]))
        result = subprocess.run([sys.executable, __file__, str(fmu), kind], capture_output=True,
                                text=True, timeout=120, env=env)  # a hang fails here
        assert result.returncode == 0, result.stderr
        assert result.stdout.startswith("False") and "not a regular file" in result.stdout, \
            (family, result.stdout)


if __name__ == "__main__":
    _child(sys.argv[1], sys.argv[2])
