"""What a SmaActuator step costs in C hosts, before and after the C front.

Each host runs 30,000 steps of 1 ms (P_in = 2.6 W, load = 0.05 kg: :data:`BENCH_P_IN_W`,
:data:`BENCH_LOAD_KG`, as the library plant step and the fmpy master it is compared with) and
times every step:
- the plain ``dlopen`` C host (``sma_fmu/fmi/hosts/fmi_host.c``): set P_in + doStep + get T;
- libcosim (sma-fmu's C host ``hosts/cosim_host.c --timing``, if libcosimpy is installed):
  one ``cosim_execution_step`` (libcosim sets, steps and reads the FMU's variables itself).
"Before" is pythonfmu's own binary with libpython in LD_PRELOAD (what the FMUs were);
"after" is the front, which also keeps one Python thread state per host thread; the front
without that keeper (SMA_FMU_NO_TSTATE=1) shows what the keeper alone is worth, and
without the fast path (SMA_FMU_NO_FAST_PATH=1: every fmi2Set/Get crosses into Python).

The floor: :func:`build_thermal_lag` compiles ``sma_fmu/bench/thermal_lag.c``, a
minimal native C FMI 2.0 co-simulation FMU of the wire's thermal first-order lag (no
Python), with the C compiler where there is one; the bench runs it in the same C host and
fmpy master as SmaActuator.
"""
import importlib.util
import shutil
import statistics
import subprocess
import sys
import tempfile
import uuid
import zipfile
from pathlib import Path

from sma_fmu.fmi.c_common import include_flags
from sma_fmu.fmi.hosts import c_compiler, compile_host
from sma_fmu.fmi.packaging.front_build import libpython_path, remove_front
from sma_fmu.systems.c_host import host_environment

__all__ = ["BENCH_LOAD_KG", "BENCH_P_IN_W", "C_HOST_STEPS", "c_host_step_costs",
           "build_thermal_lag", "plain_host_commands", "plain_host_step_us", "THERMAL_LAG_REFERENCES"]

THERMAL_LAG_REFERENCES = {"P_in": 0, "T": 1, "T_room": 2, "K_th": 3, "tau": 4, "T_start": 5}
_LAG_XML = """<?xml version="1.0" encoding="UTF-8"?>
<fmiModelDescription fmiVersion="2.0" modelName="ThermalLag" guid="{guid}"
  description="bench floor: the wire's first-order thermal lag in C (sma_fmu/bench)"
  generationTool="sma-fmu bench" variableNamingConvention="flat" numberOfEventIndicators="0">
  <CoSimulation modelIdentifier="ThermalLag" canHandleVariableCommunicationStepSize="true"/>
  <DefaultExperiment startTime="0" stopTime="30" stepSize="0.001"/>
  <ModelVariables>
    <ScalarVariable name="P_in" valueReference="0" causality="input" variability="continuous"><Real start="0"/></ScalarVariable>
    <ScalarVariable name="T" valueReference="1" causality="output" variability="continuous" initial="exact"><Real start="{T_room!r}"/></ScalarVariable>
    <ScalarVariable name="T_room" valueReference="2" causality="parameter" variability="fixed"><Real start="{T_room!r}"/></ScalarVariable>
    <ScalarVariable name="K_th" valueReference="3" causality="parameter" variability="fixed"><Real start="{K_th!r}"/></ScalarVariable>
    <ScalarVariable name="tau" valueReference="4" causality="parameter" variability="fixed"><Real start="{tau!r}"/></ScalarVariable>
    <ScalarVariable name="T_start" valueReference="5" causality="parameter" variability="fixed"><Real start="{T_room!r}"/></ScalarVariable>
  </ModelVariables>
  <ModelStructure><Outputs><Unknown index="2"/></Outputs><InitialUnknowns><Unknown index="2"/></InitialUnknowns></ModelStructure>
</fmiModelDescription>
"""

C_HOST_STEPS = 30_000
_STEP = 1e-3
BENCH_P_IN_W = 2.6     # W, every SmaActuator step of the bench
BENCH_LOAD_KG = 0.05   # kg, every SmaActuator step of the bench (C hosts, fmpy, library)


def _references(fmu):
    from sma_fmu.fmi.driving.description import read_description
    return {v.name: v.valueReference for v in read_description(fmu).modelVariables}


def _environment(extra):
    """The C host's environment without the front's switches, plus ``extra``."""
    return {**host_environment(drop=("SMA_FMU_LIBPYTHON", "SMA_FMU_NO_TSTATE",
                                     "SMA_FMU_NO_FAST_PATH", "SMA_FMU_NO_DIRECT_STEP")), **extra}


def build_thermal_lag(folder, params):
    """The bench's native C FMU ``folder/ThermalLag.fmu`` (see the module docstring), with
    T_room, K_th and tau of ``params`` (WireParameters) as defaults; (path, None), or
    (None, why) where it cannot be built (not 64-bit Linux, no working C compiler)."""
    if not (sys.platform.startswith("linux") and sys.maxsize > 2 ** 32):
        return None, f"the native bench FMU is built on 64-bit Linux only (this is {sys.platform})"
    source = Path(__file__).parent / "thermal_lag.c"
    values = {"T_room": float(params.T_room), "K_th": float(params.K_th), "tau": float(params.tau_th)}
    with tempfile.TemporaryDirectory(prefix="sma_fmu_lag_") as stage:
        library = Path(stage) / "ThermalLag.so"
        command = [*c_compiler(), "-std=c11", "-O2", "-shared", "-fPIC", "-fvisibility=hidden",
                   *include_flags(), f"-DLAG_T_ROOM={values['T_room']!r}",
                   f"-DLAG_K_TH={values['K_th']!r}", f"-DLAG_TAU={values['tau']!r}",
                   "-o", str(library), str(source), "-lm"]
        try:
            result = subprocess.run(command, capture_output=True, text=True, timeout=300)
        except (OSError, subprocess.SubprocessError) as error:
            return None, f"C compiler could not run ({error})"
        if result.returncode != 0:
            return None, f"C compiler failed: {(result.stderr.strip().splitlines() or ['?'])[-1]}"
        path = Path(folder) / "ThermalLag.fmu"
        with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as fmu:
            fmu.writestr("modelDescription.xml", _LAG_XML.format(guid=f"{{{uuid.uuid4()}}}", **values))
            fmu.write(library, "binaries/linux64/ThermalLag.so")
    return path, None


def plain_host_step_us(fmu, runs, folder, refs, init=None):
    """Median over ``runs`` of the mean [us] of set P_in + doStep + get T in fmi_host, for any
    FMU with those variables (``init``: fmi_host commands in Initialization Mode, default: the
    load set to :data:`BENCH_LOAD_KG`); a list."""
    unpacked = Path(folder) / f"unpacked-{Path(fmu).stem}"
    shutil.unpack_archive(str(fmu), str(unpacked), "zip")
    host = compile_host("fmi_host", folder)
    return [_plain_host(host, unpacked, refs, {}, init)[0] for _ in range(runs)]


def plain_host_commands(refs, init=None, steps=C_HOST_STEPS):
    """The fmi_host commands of one timed run: instantiate, initialize (``init``, default: the
    load ``refs["load"]`` set to :data:`BENCH_LOAD_KG`), then ``steps`` timed steps at
    :data:`BENCH_P_IN_W`; a list of lines."""
    init = [f"setreal 0 1 {refs['load']} {BENCH_LOAD_KG!r}"] if init is None else list(init)
    return [f"instantiate 0 {b'bench'.hex()} ok ok 0", "setup 0 0 -", "enter 0", *init, "exit 0",
            f"bench 0 {steps} {_STEP} {refs['P_in']} {BENCH_P_IN_W!r} {refs['T']} 0", "end"]


def _plain_host(exe, folder, refs, env, init=None):
    """(mean, p50, p99, p99.9) [us] of set + doStep + get in fmi_host: the percentiles of a
    pass timed step by step, the mean of a second pass timed as a whole (fmi_host.c's
    ``bench``: two clock reads per step cost as much as a native C FMU step)."""
    commands = "\n".join([*plain_host_commands(refs, init), ""])
    result = subprocess.run([str(exe), str(folder)], input=commands, capture_output=True, text=True,
                            env=_environment(env), timeout=600, check=True)
    words = [line.split() for line in result.stdout.splitlines() if line.startswith("= ")][-1]
    if words[1] != "0":
        raise RuntimeError(f"the C host's bench failed: {result.stdout[-500:]}")
    p50, p99, p999, total = map(float, words[3:7])
    return total / C_HOST_STEPS * 1e6, p50, p99, p999


def _libcosim(exe, fmu, env):
    """(mean, p50, p99, p99.9) [us] of one libcosim step."""
    result = subprocess.run(
        [str(exe), "--timing", "fmu", str(fmu), repr(_STEP), str(C_HOST_STEPS),
         f"P_in={BENCH_P_IN_W!r}", f"load={BENCH_LOAD_KG!r}"], capture_output=True, text=True, env=_environment(env), timeout=600)
    timing = [line.split() for line in result.stdout.splitlines() if line.startswith("timing ")]
    if result.returncode != 0 or not timing:
        raise RuntimeError(f"libcosim run failed: {(result.stdout + result.stderr)[-500:]}")
    p50, p99, p999, total = map(float, timing[-1][1:])
    return total / (C_HOST_STEPS - 1) * 1e6, p50, p99, p999


def c_host_step_costs(fmu, runs, folder):
    """{host and configuration: {mean_us, p50_us, p99_us, p99_9_us}} (medians of ``runs``)."""
    folder = Path(folder)
    refs = _references(fmu)
    before = remove_front(fmu, folder / "SmaActuator-pythonfmu.fmu")
    unpacked = {}
    for name, path in (("front", fmu), ("pythonfmu", before)):
        unpacked[name] = folder / f"unpacked-{name}"
        shutil.unpack_archive(str(path), str(unpacked[name]), "zip")
    preload = {"LD_PRELOAD": libpython_path()[0]}
    host = compile_host("fmi_host", folder)
    cases = {
        "plain C host, pythonfmu + LD_PRELOAD (before)": lambda: _plain_host(host, unpacked["pythonfmu"], refs, preload),
        "plain C host, front without thread-state keeper": lambda: _plain_host(
            host, unpacked["front"], refs, {"SMA_FMU_NO_TSTATE": "1"}),
        "plain C host, front without fast path": lambda: _plain_host(
            host, unpacked["front"], refs, {"SMA_FMU_NO_FAST_PATH": "1"}),
        "plain C host, front (after)": lambda: _plain_host(host, unpacked["front"], refs, {}),
    }
    if importlib.util.find_spec("libcosimpy") is not None:
        cosim = compile_host("cosim_host", folder)
        cases["libcosim step, pythonfmu + LD_PRELOAD (before)"] = lambda: _libcosim(cosim, before, preload)
        cases["libcosim step, front (after)"] = lambda: _libcosim(cosim, fmu, {})
    results = {}
    for name, measure in cases.items():
        samples = list(zip(*(measure() for _ in range(runs))))
        results[name] = {key: round(statistics.median(values), 3) for key, values in
                         zip(("mean_us", "p50_us", "p99_us", "p99_9_us"), samples)}
    return results


def _library_plant_step_us(params, steps=C_HOST_STEPS):
    """Mean [us] of the library's plant step (PlantStepper.step at BENCH_P_IN_W, BENCH_LOAD_KG)."""
    import time
    from sma_fmu.runtime.plant import PlantStepper
    stepper = PlantStepper(params, load=BENCH_LOAD_KG)
    step = stepper.step
    start = time.perf_counter()
    for _ in range(steps):
        step(BENCH_P_IN_W, BENCH_LOAD_KG, _STEP)
    return (time.perf_counter() - start) / steps * 1e6


def _master_step_us(fmu, start_values, steps=C_HOST_STEPS):
    """Mean [us] of set P_in + doStep + get T through the fmpy master's :class:`LeanStep`."""
    import time
    from sma_fmu.cosim.master import LeanStep
    from sma_fmu.fmi.driving.instance import FmuInstance
    with FmuInstance(fmu, "bench-master", start_values) as instance:
        lean = LeanStep(instance, ("P_in",), ("T",))
        inputs, step, t = lean.inputs, lean.step, 0.0
        begin = time.perf_counter()
        for _ in range(steps):
            inputs[0] = BENCH_P_IN_W
            step(t, _STEP)
            t += _STEP
        return (time.perf_counter() - begin) / steps * 1e6


def floor_costs(fmu_paths, params, runs, folder):
    """Alternating runs of SmaActuator and the native ThermalLag FMU in the C host and the fmpy
    master, and of the library's plant step: {"samples": {case: [us per run]},
    "ratios": {name: [ratio per run]}, "floor": None or why the native FMU was not built}."""
    actuator = fmu_paths["SmaActuator"]
    lag, why = build_thermal_lag(folder, params)
    refs = _references(actuator)
    cases = {
        "library plant step": lambda: _library_plant_step_us(params),
        "SmaActuator, C host": lambda: plain_host_step_us(actuator, 1, folder, refs)[0],
        "SmaActuator, fmpy master": lambda: _master_step_us(actuator, {"load": BENCH_LOAD_KG}),
    }
    if lag is not None:
        cases["ThermalLag (native C), C host"] = lambda: plain_host_step_us(
            lag, 1, folder, THERMAL_LAG_REFERENCES, init=())[0]
        cases["ThermalLag (native C), fmpy master"] = lambda: _master_step_us(lag, None)
    samples = {name: [] for name in cases}
    for _ in range(runs):  # alternating: each ratio compares runs made next to each other
        for name, measure in cases.items():
            samples[name].append(measure())
    plant = samples["library plant step"]
    pairs = {"SmaActuator in the C host / library plant step": ("SmaActuator, C host", plant),
             "SmaActuator in the fmpy master / library plant step": ("SmaActuator, fmpy master", plant)}
    if lag is not None:
        pairs.update({
            "native C FMU in the C host / library plant step": ("ThermalLag (native C), C host", plant),
            "SmaActuator / native C FMU, C host": ("SmaActuator, C host",
                                                   samples["ThermalLag (native C), C host"]),
            "SmaActuator / native C FMU, fmpy master": ("SmaActuator, fmpy master",
                                                        samples["ThermalLag (native C), fmpy master"])})
    ratios = {name: [a / b for a, b in zip(samples[case], base)] for name, (case, base) in pairs.items()}
    return {"samples": samples, "ratios": ratios, "floor": why}
