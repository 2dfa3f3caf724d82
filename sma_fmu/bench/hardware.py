"""The bench hardware in ``sma-fmu bench --only hardware``: what the sensor and the drive limit
cost per step, and the C master against the library on the bench scenarios.

- Each block's cost per step in the Python runtime and in the C runtime
  (``hardware_timing.c`` compiled with the C family's sources): the noise alone
  (:func:`~sma_fmu.runtime.noise.standard_normal`), the sensor (noise and a 16-bit ADC), the
  PI without and with its sensor (the SmaPiController FMU's step), the linear driver under a
  current limit, the PWM driver without and with a limited on-power. CPU time, the median of
  the passes: on a shared machine it counts this process's work only.
- The feedforward compensators' cost per step, Python and C: the paper's beside the minor-loop
  inverse and the shaped one with and without anticipation (:mod:`.compensator`).
- :data:`SCENARIOS` through the C master over the native FMUs against the library path,
  recording included (:func:`~sma_fmu.bench.c_master.c_master_times`), against the C
  master's target (0.25).
"""
import statistics
import subprocess
import tempfile
import time
from pathlib import Path

from sma_fmu.bench.c_master import TARGET, c_master_times
from sma_fmu.bench.compensator import CASES, compensator_costs
from sma_fmu.bench.inverse import timing_program
from sma_fmu.runtime.drive_limit import DriveLimit, LinearDriver
from sma_fmu.runtime.measurement import ResistanceSensor, SensedPIController
from sma_fmu.runtime.noise import standard_normal
from sma_fmu.runtime.pi_control import PIController
from sma_fmu.runtime.pwm import PwmDriver

__all__ = ["SCENARIOS", "BLOCKS", "python_costs", "c_costs", "run_hardware_bench",
           "hardware_lines"]

SCENARIOS = ("load-step-bench-pi+ff-adaptive", "heavy-continuous-bench-pi+ff-adaptive-minor-loop",
             # the bench's best controller: shaped, anticipating the lower turn
             "load-step-bench-pi+ff-adaptive-reachable",
             "heavy-continuous-bench-pi+ff-adaptive-reachable")
BLOCKS = {"noise": "noise z(seed, k) alone",
          "sensor": "sensor: noise + 16-bit ADC",
          "pi": "PI (no sensor)",
          "sensed_pi": "PI with its sensor (the PI FMU's step)",
          "linear_limited": "linear driver, I and V limit",
          "pwm": "PWM driver (no limit)",
          "pwm_limited": "PWM driver, limited on-power"}
STEPS = 20_000      # steps per pass


def _wire(k):
    return 40.0 + (k % 1000) * 1e-3


def _python_blocks():
    """{block: a function of the step index k}: the C program's blocks, in Python."""
    sensor = ResistanceSensor(0.05, 65.536, 16, 1)
    plain = PIController(0.3, 1.0)
    sensed = SensedPIController(0.3, 1.0, ResistanceSensor(0.05, 65.536, 16, 1))
    limit = DriveLimit(0.5, 24.0)
    linear = LinearDriver(limit)
    pwm, limited = PwmDriver(50.0, 8.0), PwmDriver(50.0, 8.0, limit)
    return {"noise": lambda k: standard_normal(1, k),
            "sensor": lambda k: sensor.measure(_wire(k)),
            "pi": lambda k: plain.sample(_wire(k), 41.0, 1.0, 1e-3)[0],
            "sensed_pi": lambda k: sensed.sample(_wire(k), 41.0, 1.0, 1e-3)[0],
            "linear_limited": lambda k: linear.step(12.0, k * 1e-3, 1e-3, _wire(k)),
            "pwm": lambda k: pwm.step(5.0, k * 1e-3, 1e-3),
            "pwm_limited": lambda k: limited.step(5.0, k * 1e-3, 1e-3, _wire(k))}


def python_costs(passes, steps=STEPS):
    """{block: CPU ns per step} of the Python runtime (median of ``passes`` passes; each pass
    includes the wire's R and a lambda call, as a loop's step would call the block)."""
    costs = {name: [] for name in BLOCKS}
    for _ in range(passes):
        for name, block in _python_blocks().items():
            start = time.process_time()
            for k in range(steps):
                block(k)
            costs[name].append((time.process_time() - start) / steps * 1e9)
    return {name: round(statistics.median(values), 1) for name, values in costs.items()}


def c_costs(folder, passes, steps=STEPS):
    """{block: CPU ns per step} of the C runtime (median of ``passes`` passes)."""
    program = timing_program(folder, "hardware_timing")
    result = subprocess.run([str(program)], input=f"{passes} {steps}", capture_output=True,
                            text=True)
    if result.returncode != 0:
        raise RuntimeError(f"the hardware timing program failed: {result.stderr.strip()}")
    costs = {name: [] for name in BLOCKS}
    for line in result.stdout.splitlines():
        name, cost, _ = line.split()
        costs[name].append(float(cost))
    return {name: round(statistics.median(values), 2) for name, values in costs.items()}


def run_hardware_bench(out_dir, runs=5, native_dir=None, progress=print):
    """The section (see the module docstring); returns the results, also written to
    ``out_dir``/benchmark.json (the native FMUs built there unless ``native_dir`` holds them)."""
    from sma_fmu.files.json_output import json_text
    from sma_fmu.files.output_folder import staged_folder

    with staged_folder(out_dir) as stage, tempfile.TemporaryDirectory() as work:
        progress("each block per step, Python and C ...")
        costs = {"python_ns": python_costs(max(runs, 3)), "c_ns": c_costs(work, max(runs, 3))}
        progress("the compensators per step, Python and C ...")
        compensators = compensator_costs(work, max(runs, 3))
        if native_dir is None:
            from sma_fmu.fmi.packaging.c_family_build import build_native_fmus
            progress("building the native FMUs ...")
            native_dir = Path(build_native_fmus(stage / "native-fmus")["SmaActuator"]).parent
        progress(f"C master against the library on the bench scenarios ({runs} alternating runs) ...")
        times = c_master_times(native_dir, runs, Path(work) / "runs", SCENARIOS, ("parquet",))
        results = {"hardware": {"per_step": costs, "compensator_per_step": compensators,
                                "c_master": times, "target": TARGET, "steps_per_pass": STEPS}}
        (stage / "benchmark.json").write_text(json_text(results), encoding="utf-8")
    return results


def hardware_lines(results):
    """The section as plain-text lines."""
    section = results["hardware"]
    python, c = section["per_step"]["python_ns"], section["per_step"]["c_ns"]
    lines = [f"{'block, per step [CPU ns]':<46}{'Python':>10}{'C':>10}"]
    lines += [f"{text:<46}{python[name]:>10.1f}{c[name]:>10.2f}" for name, text in BLOCKS.items()]
    compensators = section.get("compensator_per_step")
    if compensators:
        lines += ["", f"{'compensator, per step [CPU ns]':<46}{'Python':>10}{'C':>10}"]
        lines += [f"{CASES[case][0]:<46}{row['python_ns']:>10.1f}{row['c_ns']:>10.2f}"
                  for case, row in compensators.items()]
    lines += ["", "C master (--master c) / library on the bench scenarios, recording included"]
    for name, row in section["c_master"].items():
        verdict = "meets" if row["ratio"] <= section["target"] else "MISSES"
        lines.append(f"{name:<62}{row['library_s']:>8.3f} s{row['c_s']:>8.3f} s{row['ratio']:>8.3f}"
                     f"  ({row['min']:.3f} ... {row['max']:.3f})  {verdict} target <= "
                     f"{section['target']:g}")
    return lines
