"""The native (C) FMUs refuse pointers that are not live instances (core/layer_instances.c).

A host calling with a freed instance, freeing one twice, or passing memory that never was an
instance gets fmi2Error (fmi2FreeInstance: nothing) and one stderr line, and no other instance
is touched: a stale pointer never reaches the instance made after it. The binary is driven
through ctypes (CDLL releases the GIL in a call, so the threads below run the C code at once).
"""
import ctypes
import threading
import zipfile

import pytest
from fmpy import read_model_description

pytestmark = pytest.mark.needs("gcc")

ERROR = 3
STEP_S = 1e-2  # communication step [s]
STEPS = 60
MODEL = "SmaActuator"


class Binary:
    """The linux64 binary of a native FMU, its ctypes signatures set, and its variables."""

    def __init__(self, fmu, folder):
        with zipfile.ZipFile(fmu) as archive:
            archive.extractall(folder)
        description = read_model_description(str(fmu))
        self.vr = {v.name: v.valueReference for v in description.modelVariables}
        self.outputs = [v.name for v in description.modelVariables
                        if v.causality == "output" and v.type == "Real"]
        self.guid = description.guid.encode()
        self.uri = (folder / "resources").as_uri().encode()
        lib = self.lib = ctypes.CDLL(str(folder / "binaries" / "linux64" / f"{fmu.stem}.so"))
        lib.fmi2Instantiate.restype = ctypes.c_void_p
        lib.fmi2Instantiate.argtypes = [ctypes.c_char_p, ctypes.c_int, ctypes.c_char_p,
                                        ctypes.c_char_p, ctypes.c_void_p, ctypes.c_int, ctypes.c_int]
        pointer, real_array = ctypes.c_void_p, ctypes.POINTER(ctypes.c_double)
        references = ctypes.POINTER(ctypes.c_uint)
        lib.fmi2FreeInstance.argtypes = [pointer]
        lib.fmi2FreeInstance.restype = None
        lib.fmi2SetupExperiment.argtypes = [pointer, ctypes.c_int, ctypes.c_double, ctypes.c_double,
                                            ctypes.c_int, ctypes.c_double]
        for name in ("fmi2EnterInitializationMode", "fmi2ExitInitializationMode", "fmi2Terminate"):
            getattr(lib, name).argtypes = [pointer]
        lib.fmi2DoStep.argtypes = [pointer, ctypes.c_double, ctypes.c_double, ctypes.c_int]
        for name in ("fmi2SetReal", "fmi2GetReal"):
            getattr(lib, name).argtypes = [pointer, references, ctypes.c_size_t, real_array]

    def instantiate(self, name):
        component = self.lib.fmi2Instantiate(name.encode(), 1, self.guid, self.uri, None, 0, 0)
        assert component, name
        return component

    def set_real(self, component, values):
        """fmi2SetReal of {name: value}; its status."""
        vr = (ctypes.c_uint * len(values))(*(self.vr[n] for n in values))
        return self.lib.fmi2SetReal(component, vr, len(values), (ctypes.c_double * len(values))(*values.values()))

    def get_real(self, component, names):
        """(status, [values]) of fmi2GetReal."""
        vr = (ctypes.c_uint * len(names))(*(self.vr[n] for n in names))
        out = (ctypes.c_double * len(names))()
        return self.lib.fmi2GetReal(component, vr, len(names), out), list(out)

    def start(self, component, power_W):
        """Setup, initialization with P_in = ``power_W``; all must succeed."""
        lib = self.lib
        assert lib.fmi2SetupExperiment(component, 0, 0.0, 0.0, 0, 0.0) == 0
        assert lib.fmi2EnterInitializationMode(component) == 0
        assert self.set_real(component, {"P_in": power_W}) == 0
        assert lib.fmi2ExitInitializationMode(component) <= 1

    def step(self, component, index):
        """Step number ``index`` (from t = 0); its status."""
        return self.lib.fmi2DoStep(component, index * STEP_S, STEP_S, 1)

    def run(self, name, power_W):
        """A fresh instance's outputs after STEPS steps (freed afterwards)."""
        component = self.instantiate(name)
        self.start(component, power_W)
        for i in range(STEPS):
            assert self.step(component, i) <= 1
        status, values = self.get_real(component, self.outputs)
        assert status <= 1
        self.lib.fmi2FreeInstance(component)
        return values


@pytest.fixture(scope="module")
def binary(native_fmus, tmp_path_factory):
    return Binary(native_fmus[MODEL], tmp_path_factory.mktemp("native_instances"))


def test_free_twice_is_harmless(binary, capfd):
    """The second fmi2FreeInstance does nothing but say so; instances made after it work."""
    reference = binary.run("reference", 0.4)
    capfd.readouterr()
    component = binary.instantiate("twice")
    binary.start(component, 0.4)
    binary.lib.fmi2FreeInstance(component)
    binary.lib.fmi2FreeInstance(component)
    err = capfd.readouterr().err
    assert err.splitlines() == ["sma-fmu native: fmi2FreeInstance: refused: instance 'twice' was "
                                "freed by fmi2FreeInstance"]
    assert binary.run("after", 0.4) == reference


def test_stale_pointer_is_refused_and_never_reaches_a_new_instance(binary, capfd):
    """Free A, make B (the allocator would like to give it A's address): set, step and free
    with A's pointer between B's steps give fmi2Error; B ends where a fresh instance does."""
    power_W = 0.5
    reference = binary.run("fresh", power_W)
    a = binary.instantiate("plant")
    binary.start(a, 0.2)
    assert binary.step(a, 0) <= 1
    binary.lib.fmi2FreeInstance(a)
    b = binary.instantiate("successor")
    binary.start(b, power_W)
    capfd.readouterr()
    for i in range(STEPS):
        assert binary.set_real(a, {"P_in": 0.0}) == ERROR
        assert binary.step(a, i) == ERROR
        assert binary.get_real(a, ["x"])[0] == ERROR
        assert binary.lib.fmi2Terminate(a) == ERROR
        assert binary.step(b, i) <= 1
    binary.lib.fmi2FreeInstance(a)
    err = capfd.readouterr().err.splitlines()
    assert len(err) == 4 * STEPS + 1
    for function in ("fmi2SetReal", "fmi2DoStep", "fmi2GetReal", "fmi2Terminate", "fmi2FreeInstance"):
        assert (f"sma-fmu native: {function}: refused: instance 'plant' was freed by "
                "fmi2FreeInstance") in err, function
    status, values = binary.get_real(b, binary.outputs)
    assert status <= 1 and values == reference
    assert values != binary.run("other power", 0.2)  # the outputs tell the inputs apart
    binary.lib.fmi2FreeInstance(b)


@pytest.mark.parametrize("size", [8, 4096])
def test_pointer_never_an_instance_is_refused(binary, capfd, size):
    """The address of a buffer of zeros (small and large) and NULL: fmi2Error, the buffer is
    neither read as an instance nor written, one stderr line per call (none for NULL)."""
    buffer = ctypes.create_string_buffer(size)
    foreign = ctypes.addressof(buffer)
    capfd.readouterr()
    assert binary.step(foreign, 0) == ERROR
    assert binary.set_real(foreign, {"P_in": 1.0}) == ERROR
    assert binary.get_real(foreign, ["x"])[0] == ERROR
    assert binary.lib.fmi2EnterInitializationMode(foreign) == ERROR
    binary.lib.fmi2FreeInstance(foreign)
    assert buffer.raw == bytes(size)
    err = capfd.readouterr().err.splitlines()
    assert len(err) == 5
    assert all(line.startswith("sma-fmu native: fmi2") and "is no instance of this FMU" in line
               for line in err), err
    assert binary.step(None, 0) == ERROR
    binary.lib.fmi2FreeInstance(None)
    assert capfd.readouterr().err == ""


def test_threads_make_step_and_free_their_own_instances(binary):
    """Four threads, each making, stepping and freeing instances in a loop at once, all end
    with the outputs a single thread computes for the same input."""
    powers_W = [0.1, 0.3, 0.5, 0.7]
    expected = {power: binary.run(f"alone {power}", power) for power in powers_W}
    results, failures = {}, []

    def work(power):
        try:
            results[power] = [binary.run(f"thread {power} round {r}", power) for r in range(6)]
        except Exception as error:  # a failure in a thread: reported by the test
            failures.append((power, repr(error)))

    threads = [threading.Thread(target=work, args=(power,)) for power in powers_W]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    assert not failures
    for power in powers_W:
        assert results[power] == [expected[power]] * 6, power
    assert len({tuple(values) for values in expected.values()}) == len(powers_W)
