"""The FMUs in hosts that are not Python, with no environment variable set (no LD_PRELOAD).

- libcosim (Open Simulation Platform, from the libcosimpy wheel) driven from a C program,
  sma-fmu's C host (sma_fmu/fmi/hosts/cosim_host.c): it loads the FMU through the FMI Library;
- a plain dlopen C host (sma_fmu/fmi/hosts/fmi_host.c), as fmusim does;
- fmpy under a Python linked into its executable: Debian's /usr/bin/python3 when it is the
  running minor version, else one linked from the running Python's libpython3.X.a (the front
  must use that process's Python, not load a second libpython).
The results equal the library steppers'. Without the C front (no C compiler at build
time) the FMU's binary is pythonfmu's own, which does not load in a C host.
"""
import re
import shutil
import subprocess
import sys
import sysconfig
import warnings
import zipfile
from pathlib import Path

import pytest
from fmpy import read_model_description

from fmi_host import ERROR, OK, WARNING, FmiHost, text, unpack
from sma_fmu.fmi.packaging.build import build_fmu
from sma_fmu.fmi.packaging.front_build import FrontWarning, remove_front
from sma_fmu.fmi.hosts import CHostError, c_compiler, compile_host
from sma_fmu.runtime.feedforward import FeedforwardStepper
from sma_fmu.runtime.plant import PlantStepper
from sma_fmu.systems.c_host import host_environment
from system_needs import need, needs

import libcosimpy  # noqa: E402,F401 - the test extra; the libcosim C host links its libcosimc


def _clean_env(**extra):
    return {**host_environment(drop=("SMA_FMU_LIBPYTHON",)), **extra}


@pytest.fixture(scope="module")
def cosim_host(tmp_path_factory):
    need("gcc")
    return compile_host("cosim_host", tmp_path_factory.mktemp("c_host"))


def _run(exe, fmu, step, steps, start_values, outputs, env=None):
    """Run ``fmu`` alone in the C host; returns (the process, {output in ``outputs``: value})."""
    args = [str(exe), "fmu", str(fmu), repr(step), str(steps)]
    args += [f"{name}={value!r}" for name, value in start_values.items()]
    result = subprocess.run(args, capture_output=True, text=True, env=env or _clean_env(), timeout=120)
    values = {}
    for line in result.stdout.splitlines():  # libcosim also logs to stdout
        match = re.fullmatch(r"fmu\.(\w+)=(\S+)", line.strip())
        if match and match.group(1) in outputs:
            values[match.group(1)] = float(match.group(2))
    return result, values


def test_plant_fmu_runs_in_libcosim_without_ld_preload(cosim_host, fmus, params):
    result, values = _run(cosim_host, fmus["SmaActuator"], 1e-3, 5000,
                          {"P_in": 2.6, "load": 0.05}, ["R", "T", "xi_F"])
    assert result.returncode == 0, result.stdout[-2000:] + result.stderr[-2000:]
    library = PlantStepper(params, load=0.05)
    for _ in range(5000):
        out = library.step(2.6, 0.05, 1e-3)
    # libcosim passes h as (1e6 ns) * 1e-9 s: equal up to that rounding
    assert values["T"] == pytest.approx(out.T, abs=1e-9)
    assert values["R"] == pytest.approx(out.R, abs=1e-9)
    assert values["xi_F"] == pytest.approx(out.xi_F, abs=1e-12)
    assert out.R < 48.0  # the run went into the transformation


def test_feedforward_fmu_runs_in_libcosim_without_ld_preload(cosim_host, fmus, params):
    result, values = _run(cosim_host, fmus["SmaFeedforward"], 1e-3, 500,
                          {"R_ref": 42.0, "load": 0.15}, ["P_ff", "T_ref"])
    assert result.returncode == 0, result.stdout[-2000:] + result.stderr[-2000:]
    library = FeedforwardStepper(params)
    for _ in range(500):
        out = library.step(42.0, 0.15, 1e-3)
    assert values["T_ref"] == pytest.approx(out.T_ref, abs=1e-9)
    assert values["P_ff"] == pytest.approx(out.P_ff, abs=1e-9)


def test_c_host_timing_and_start_value_errors(cosim_host, fmus):
    fmu = fmus["SmaActuator"]
    plain, values = _run(cosim_host, fmu, 1e-3, 50, {"P_in": 2.6}, ["R", "T"])
    timed = subprocess.run([str(cosim_host), "--timing", "fmu", str(fmu), "0.001", "50", "P_in=2.6"],
                           capture_output=True, text=True, env=_clean_env(), timeout=120)
    assert plain.returncode == 0 and timed.returncode == 0, timed.stderr
    timing = [line.split() for line in timed.stdout.splitlines() if line.startswith("timing ")]
    assert len(timing) == 1 and len(timing[0]) == 5
    p50, p99, p999, total = map(float, timing[0][1:])
    assert 0 < p50 <= p99 <= p999 and total > 0
    # stepping one step at a time computes the same outputs, to the last digit
    assert [line for line in timed.stdout.splitlines() if line.startswith("fmu.")] == [
        line for line in plain.stdout.splitlines() if line.startswith("fmu.")]
    assert set(values) == {"R", "T"}
    for start, message in (({"P_inn": 1.0}, "the FMU has no Real variable 'P_inn'"),
                           ({"hysteresis_mode": 1.0}, "no Real variable 'hysteresis_mode'")):
        result, values = _run(cosim_host, fmu, 1e-3, 5, start, ["R"])
        assert result.returncode == 2 and message in result.stderr and not values
    for args, message in ((["fmu", str(fmu), "0.001", "5", "P_in=2.6W"], "bad start value 'P_in=2.6W'"),
                          (["ssp", str(fmu), "0.001", "5", "P_in=1"], "are for an FMU, not an SSP"),
                          (["--timing", "fmu", str(fmu), "0.001", "1"], "STEPS >= 2"),
                          (["fmi", str(fmu), "0.001", "5"], "usage: cosim_host")):
        result = subprocess.run([str(cosim_host), *args], capture_output=True, text=True,
                                env=_clean_env(), timeout=120)
        assert result.returncode == 2 and message in result.stderr, result.stderr


def test_host_environment_drops_ld_preload_and_the_keys_asked():
    environment = {"LD_PRELOAD": "/lib/libpython.so", "SMA_FMU_LIBPYTHON": "/lib/x.so", "PATH": "/bin"}
    assert host_environment(environment) == {"SMA_FMU_LIBPYTHON": "/lib/x.so", "PATH": "/bin"}
    assert host_environment(environment, drop=("SMA_FMU_LIBPYTHON",)) == {"PATH": "/bin"}
    assert "LD_PRELOAD" in environment  # the caller's mapping is left as it was


@needs("gcc")
def test_cc_is_split_like_a_shell(monkeypatch, tmp_path):
    """CC="ccache gcc" style: a compiler command with words, as make and the build take it."""
    monkeypatch.setenv("CC", f"{shutil.which('gcc')} -O0")
    assert c_compiler() == [shutil.which("gcc"), "-O0"]
    host = compile_host("fmi_host", tmp_path)
    assert host.is_file() and host.parent.parent == tmp_path
    assert compile_host("fmi_host", tmp_path) == host  # cached: built once
    monkeypatch.setenv("CC", str(tmp_path / "no-such-compiler"))
    with pytest.raises(CHostError, match="no-such-compiler.*could not run to build fmi_host"):
        compile_host("fmi_host", tmp_path)


def _start(host, name="plant", uri="ok", logging=0):
    reply = host.call(f"instantiate 0 {text(name)} {uri} ok {logging}")
    if reply.status == OK:
        for line in ("setup 0 0 -", "enter 0", "exit 0"):
            assert host.call(line).status == OK
    return reply


def test_plain_c_host_equals_the_library(fmi_host_exe, unpacked, params):
    library = PlantStepper(params, load=0.05)
    with FmiHost(fmi_host_exe, unpacked["SmaActuator"]) as host:
        assert _start(host).status == OK
        for k in range(2000):
            assert host.call(f"setreal 0 2 0 {1.4!r} 1 {0.05!r}").status == OK
            assert host.call(f"step 0 {k * 1e-3!r} {1e-3!r}").status == OK
            out = library.step(1.4, 0.05, 1e-3)
        values = host.call("getreal 0 2 2 3").values
        assert host.close() == 0
    assert [float(v) for v in values] == [out.R, out.T]


@pytest.mark.parametrize("uri", ["ok", "one", "localhost", "plain", "pct"])
def test_resource_uris_that_name_the_folder_work(fmi_host_exe, unpacked, uri):
    with FmiHost(fmi_host_exe, unpacked["SmaActuator"]) as host:
        reply = _start(host, uri=uri)
        assert reply.status == OK
        assert host.call("step 0 0 0.001").status == OK
        assert bool(reply.logged(WARNING)) == (uri == "plain")  # a path is not a URI: warned


@pytest.mark.parametrize("uri", ["empty", "null", "missing", "http", "relative", text("file:///%zz")])
def test_unusable_resource_uris_give_null_and_a_message(fmi_host_exe, unpacked, uri):
    with FmiHost(fmi_host_exe, unpacked["SmaFeedforward"]) as host:
        reply = host.call(f"instantiate 0 {text('ff')} {uri} ok 0")
        assert reply.status == ERROR  # the host prints 3 for a NULL instance
        assert any("fmuResourceLocation" in m or "resource folder" in m for m in reply.logged(ERROR))
        assert _start(host).status == OK  # the process is fine: the next instance works
        assert host.close() == 0


def test_format_characters_are_logged_literally(fmi_host_exe, unpacked):
    """'%' in an instance name or a String parameter reaches a printf-style logger as text."""
    # the signals' reference table: hysteresis_mode, the plant's String once, is an Integer
    table_ref = {v.name: v.valueReference for v in read_model_description(
        str(unpacked["SmaScenarioSignals"] / "modelDescription.xml")).modelVariables}["reference"]
    with FmiHost(fmi_host_exe, unpacked["SmaScenarioSignals"]) as host:
        assert host.call(f"instantiate 0 {text('valve 50%s%n')} ok ok 1").status == OK
        assert host.call("setup 0 0 -").status == OK
        assert host.call(f"setstring 0 1 {table_ref} {text('%s%s%n%x')}").status == OK
        assert host.call("enter 0").status == OK
        reply = host.call("exit 0")
        assert reply.status == ERROR
        assert any("'valve 50%s%n'" in m and "'%s%s%n%x'" in m for m in reply.logged(ERROR))
        assert host.close() == 0


def test_errors_are_logged_with_logging_off_unless_switched_off(fmi_host_exe, unpacked):
    with FmiHost(fmi_host_exe, unpacked["SmaActuator"]) as host:
        assert _start(host, logging=0).status == OK
        reply = host.call("setreal 0 1 2 1.0")             # R is an output
        assert reply.status == ERROR and "R (value reference 2)" in reply.logged(ERROR)[0]
        assert host.call("debuglog 0 0 0").status == OK     # everything off, errors too
        reply = host.call("setreal 0 1 2 1.0")
        assert reply.status == ERROR and not reply.logs
        assert host.call(f"debuglog 0 1 1 {text('logStatusError')}").status == OK
        assert host.call("setreal 0 1 2 1.0").logged(ERROR)


def test_a_discarded_step_can_be_retried_and_a_repeated_one_terminates(fmi_host_exe, unpacked):
    with FmiHost(fmi_host_exe, unpacked["SmaActuator"]) as host:
        assert _start(host).status == OK
        assert host.call("step 0 0 0.001").status == OK
        assert host.call("setreal 0 1 0 nan").status == OK
        reply = host.call("step 0 0.001 0.001")
        assert reply.status == 2 and "P_in must be finite, got nan" in reply.logged(2)[0]
        assert host.call("boolstatus 0 3").values == ["0"]         # fmi2Terminated: no
        assert float(host.call("realstatus 0 2").values[0]) == 0.001  # last successful time
        assert host.call("setreal 0 1 0 1.0").status == OK           # the master fixes P_in
        assert host.call("step 0 0.001 0.001").status == OK
        assert host.call("setreal 0 1 0 nan").status == OK
        assert host.call("step 0 0.002 0.001").status == 2
        assert host.call("step 0 0.002 0.001").status == 2             # retried unchanged
        assert host.call("boolstatus 0 3").values == ["1"]


def test_states_in_a_c_host(fmi_host_exe, unpacked):
    with FmiHost(fmi_host_exe, unpacked["SmaActuator"]) as host:
        assert _start(host).status == OK
        assert host.call("setreal 0 2 0 2.0 1 0.05").status == OK
        assert host.call("step 0 0 0.5").status == OK
        assert host.call("getstate 0 0").status == OK
        saved = host.call("serialize 0 0")
        assert saved.status == OK
        before = host.call("getreal 0 1 3").values
        assert host.call("step 0 0.5 0.5").status == OK
        corrupted = bytearray(bytes.fromhex(saved.values[0]))
        corrupted[len(corrupted) // 2] ^= 0x55
        for data in (corrupted.hex(), b"garbage".hex(), "_"):
            reply = host.call(f"deserialize 0 1 {data}")
            assert reply.status == ERROR and "not a state serialized by this FMU" in reply.logged(ERROR)[0]
        assert host.call("setstate 0 3").status == ERROR             # never saved: refused
        assert host.call(f"deserialize 0 1 {saved.values[0]}").status == OK
        assert host.call("setstate 0 1").status == OK
        assert host.call("getreal 0 1 3").values == before
        assert host.call("freestate 0 1").status == OK
        assert host.call("setstate 0 1").status == ERROR             # freed: refused
        assert host.call("step 0 0.5 0.5").status == OK
        assert host.close() == 0


def test_without_a_compiler_the_build_keeps_pythonfmus_binary_and_says_so(
        fmi_host_exe, tmp_path, monkeypatch, cosim_host):
    monkeypatch.setenv("CC", str(tmp_path / "no-such-compiler"))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        path = build_fmu("SmaActuator", tmp_path / "out")
    assert any(issubclass(w.category, FrontWarning) and "no-such-compiler" in str(w.message)
               and "LD_PRELOAD" in str(w.message) for w in caught)
    names = zipfile.ZipFile(path).namelist()
    assert "binaries/linux64/SmaActuator.so" in names
    assert not any(n.endswith("_pythonfmu.so") for n in names)
    result, values = _run(cosim_host, path, 1e-3, 10, {}, ["R"])  # pythonfmu alone: needs libpython
    assert result.returncode != 0 and not values
    assert "undefined symbol" in result.stdout + result.stderr


@needs("gcc", "mingw-w64")  # the win64 binaries too
def test_remove_front_gives_back_pythonfmus_binary(fmus, tmp_path, cosim_host):
    """The benchmark's "before": the FMU as pythonfmu wrote it, which needs libpython preloaded."""
    fmu = fmus["SmaActuator"]
    before = remove_front(fmu, tmp_path / "before.fmu")
    with zipfile.ZipFile(fmu) as front, zipfile.ZipFile(before) as plain:
        binaries = {"binaries/linux64/SmaActuator.so": "binaries/linux64/SmaActuator_pythonfmu.so",
                    "binaries/win64/SmaActuator.dll": "binaries/win64/SmaActuator_pythonfmu.dll"}
        assert sorted(plain.namelist()) == sorted(
            n for n in front.namelist() if n not in binaries.values())
        for binary, backend in binaries.items():
            assert plain.read(binary) == front.read(backend)
            assert plain.read(binary) != front.read(binary)
        assert b"VendorAnnotations" in front.read("modelDescription.xml")
        assert b"VendorAnnotations" not in plain.read("modelDescription.xml")
        assert all(plain.read(n) == front.read(n) for n in plain.namelist()
                   if n not in binaries and n != "modelDescription.xml")
    result, values = _run(cosim_host, before, 1e-3, 10, {}, ["R"])
    assert result.returncode != 0 and not values
    assert "undefined symbol" in result.stdout + result.stderr


STATIC_MAIN = "#include <Python.h>\nint main(int argc, char** argv) { return Py_BytesMain(argc, argv); }\n"


def _python_with_python_built_in(folder):
    """(executable, extra environment) of a Python of the running minor version that has Python
    linked into the executable, as Debian's /usr/bin/python3 does: Debian's own when its minor
    is the running one, else one linked here from the running Python's libpython3.X.a (what
    the venv's numpy and fmpy are built for; Debian's python3 could not load them)."""
    minor = "%d.%d" % sys.version_info[:2]
    debian = Path("/usr/bin/python3")
    assert debian.is_file(), "Debian's python3 is part of the test machine"
    debian_minor = subprocess.run([str(debian), "-c", "import sys; print('%d.%d' % sys.version_info[:2])"],
                                  capture_output=True, text=True, check=True).stdout.strip()
    if debian_minor == minor:
        return debian, {}
    archive = Path(sysconfig.get_config_var("LIBPL") or "") / (sysconfig.get_config_var("LIBRARY") or "")
    assert archive.name.endswith(".a") and archive.is_file(), (
        f"Debian's python3 is {debian_minor}, this Python {minor} ships no static libpython "
        f"({archive}) to link one of its version")
    source = folder / "static_python.c"
    source.write_text(STATIC_MAIN)
    executable = folder / f"python{minor}-static"
    flags = [flag for name in ("LINKFORSHARED", "LIBS", "SYSLIBS", "MODLIBS", "LOCALMODLIBS")
             for flag in (sysconfig.get_config_var(name) or "").split()]
    subprocess.run([*c_compiler(), str(source), f"-I{sysconfig.get_config_var('INCLUDEPY')}", "-o",
                    str(executable), str(archive), *flags], check=True, capture_output=True, text=True)
    return executable, {"PYTHONHOME": sys.base_prefix}


@needs("gcc", "python3")
def test_fmpy_in_debians_static_python_uses_that_python(fmus, tmp_path):
    """The front must not load a second libpython into a process that has Python built in."""
    python, environment = _python_with_python_built_in(tmp_path)
    libraries = subprocess.run(["ldd", str(python)], capture_output=True, text=True, check=True).stdout
    assert "libpython" not in libraries, libraries  # Python is in the executable itself
    import fmpy
    script = tmp_path / "run.py"
    script.write_text(
        "import sys\nfrom fmpy import simulate_fmu\n"
        "r = simulate_fmu(sys.argv[1], stop_time=1.0, step_size=1e-3, output_interval=1e-3,"
        " start_values={'P_in': 2.0, 'load': 0.05}, output=['T'])\n"
        "maps = open('/proc/self/maps').read()\n"
        "print('%d.%d' % sys.version_info[:2], sorted({l.split()[-1] for l in maps.splitlines() if 'libpython' in l}),"
        " r['T'][-1])\n")
    site = str(Path(fmpy.__file__).parent.parent)
    result = subprocess.run([str(python), str(script), str(fmus["SmaActuator"])], capture_output=True,
                            text=True, env=_clean_env(PYTHONPATH=site, **environment), timeout=120)
    assert result.returncode == 0, result.stderr[-2000:]
    version, rest = result.stdout.strip().split(" ", 1)
    libraries, temperature = rest.rsplit(" ", 1)
    assert version == "%d.%d" % sys.version_info[:2]
    assert libraries == "[]"  # no libpython mapped: the executable's own Python ran the FMU
    assert 20.0 < float(temperature) < 60.0
