"""How well can any controller track a scenario's reference? A lower bound and benchmarks.

For a scenario (reference, loads, hysteresis mode, wire) and powers 0 <= P <= P_max, where
P_max = min(P_cap, I_max^2 R, V_max^2 / R) may depend on the wire's resistance through the
driver's current and voltage limit (the scenario's ``[drive]``, :mod:`.power_limit`):

- **saturation bound** (any mode): where R_ref lies outside the band the wire can reach
  at the load (:func:`~sma_fmu.runtime.reachable_band.reachable_band`), no controller gets
  closer than the band's edge. Rigorous; 0 when the reference stays inside the band.
- **lower bound**: mode "switch": the cell dynamic program of :mod:`.switch_dp`, rigorous
  for the model as implemented (with the thermal limit: cooling is passive). Mode
  "continuous": the saturation bound only. Relaxations of the hysteresis to the major
  loop give 0 there for the paper's reference (at one temperature the band between the
  major branches covers it), so this module does not pretend to more.
- **benchmarks**: power sequences replayed through the runtime plant, so each RMSE is
  reachable: mode "switch": the node program's path; mode "continuous": the one-step
  inverse of :mod:`.inverse_tracker` with a few passive-cooling tolerances and, on request,
  the receding-horizon search with preview of :mod:`.preview_search` at a few horizons
  (minutes; it beats the one-step inverse there by far).

The optimum lies between the lower bound and the best benchmark; their difference says
how tight the bound is. Each benchmark also reports its peak power and how often the
temperature reverses: the best continuous-mode benchmarks chatter at the step rate, which
no real driver and wire would follow, so the best one with at most
:data:`SMOOTH_REVERSALS_PER_S` reversals per second is reported as well. Units: ohm, W, s.

**Stroke** (a scenario whose reference is a stroke, mapped to R_ref through the model): the
same bound for the stroke, in micrometres (:func:`stroke_bound`). The saturation bound is the
stroke reference's distance to what the wire gives at the load (the stroke map's clamp); the
benchmarks are the same power sequences, their strokes x_0 - x replayed through the plant. The
benchmarks track R_ref, so what R cannot tell (on a minor branch the wire is at another
temperature than the map's major branch, and thermal expansion moves x) is in their stroke
error too: they bound what a self-sensing controller reaches, not one that measures x.
"""
import time
from dataclasses import asdict, dataclass

import numpy as np

from sma_fmu.cosim.metrics import band_edges

from .inverse_tracker import track
from .power_limit import PowerLimit
from .preview_search import HORIZONS, preview_search
from .switch_dp import cell_lower_bound, node_path, replay_path
from .tracking_problem import TemperatureGrid, TrackingProblem

__all__ = ["Benchmark", "TrackingBound", "TOLERANCES", "SMOOTH_REVERSALS_PER_S",
           "saturation_bound", "reversal_rate", "stroke_bound", "tracking_bound"]

TOLERANCES = (0.0, 0.01, 0.02, 0.03)  # ohm: passive-cooling tolerances of the continuous benchmark
SMOOTH_REVERSALS_PER_S = 10.0         # 1/s: a benchmark reversing at most this often does not chatter


@dataclass(frozen=True)
class Benchmark:
    """A power sequence replayed through the plant: its RMSE [ohm], peak power [W] and
    temperature reversals per second [1/s], both over the metric window."""

    method: str
    rmse_ohm: float
    peak_W: float
    reversals_per_s: float


@dataclass(frozen=True)
class TrackingBound:
    """The bound of one scenario (RMSE over the metric window, in ohm).

    lower_bound_ohm <= the best RMSE any controller reaches <= min of the benchmarks.
    """

    scenario: str
    hysteresis_mode: str
    power_cap_W: object
    current_limit_A: object     # I_max [A] of the driver, or None
    voltage_limit_V: object     # V_max [V] of the driver, or None
    saturation_bound_ohm: float
    lower_bound_ohm: float
    lower_bound_method: str
    benchmarks: tuple
    seconds: float
    stroke: dict = None         # the stroke's bound [um] (:func:`stroke_bound`), or None

    @property
    def achievable(self):
        """The best :class:`Benchmark`."""
        return min(self.benchmarks, key=lambda b: b.rmse_ohm)

    @property
    def smooth(self):
        """The best benchmark with at most SMOOTH_REVERSALS_PER_S reversals per second, or None."""
        smooth = [b for b in self.benchmarks if b.reversals_per_s <= SMOOTH_REVERSALS_PER_S]
        return min(smooth, key=lambda b: b.rmse_ohm) if smooth else None

    def as_dict(self):
        """JSON-ready fields, with the best and the best smooth benchmark."""
        fields = asdict(self)
        fields["achievable"] = asdict(self.achievable)
        fields["smooth"] = None if self.smooth is None else asdict(self.smooth)
        return fields


def saturation_bound(problem):
    """RMSE [ohm] forced by R_ref leaving the reachable band: its distance to the band's edge."""
    hot, cold = band_edges(problem.sample_loads, problem.params)
    references = problem.references
    distance = np.maximum(hot - references, 0.0) + np.maximum(references - cold, 0.0)
    return problem.rmse(np.sum(problem.weights * distance ** 2))


def reversal_rate(problem, powers):
    """Direction changes of the temperature per second [1/s] under ``powers`` [W], metric window."""
    temperatures = [problem.T_start]
    for power in powers.tolist():
        temperatures.append(problem.after_step(temperatures[-1], power))
    signs = np.sign(np.diff(temperatures))[problem.weights[1:] > 0]
    signs = signs[signs != 0]
    return float(np.count_nonzero(np.diff(signs))) / (np.sum(problem.weights[1:]) * problem.step_s)


def stroke_bound(scenario, problem, runs):
    """The stroke's bound [um] of a stroke scenario: {"saturation_bound_um", "lower_bound_um",
    "benchmarks": [{"method", "rmse_um"}], "achievable_um", "smooth_um"}. ``runs`` are
    (Benchmark, powers [W]) pairs; the lower bound is the saturation bound (the switch-mode
    cell program bounds the R error, not the stroke's)."""
    reference = scenario.reference
    times = np.arange(problem.steps + 1) * problem.step_s
    reached = np.array([reference.map.target(stroke, load, reference.signal.trend(t)).stroke
                        for stroke, load, t in zip(problem.stroke_references.tolist(),
                                                   problem.sample_loads.tolist(), times.tolist())])
    saturation = problem.stroke_rmse_um(reached)
    benchmarks = [{"method": benchmark.method,
                   "rmse_um": problem.stroke_rmse_um(problem.replay_strokes(powers)),
                   "reversals_per_s": benchmark.reversals_per_s} for benchmark, powers in runs]
    smooth = [b["rmse_um"] for b in benchmarks if b["reversals_per_s"] <= SMOOTH_REVERSALS_PER_S]
    return {"saturation_bound_um": saturation, "lower_bound_um": saturation,
            "benchmarks": benchmarks, "achievable_um": min(b["rmse_um"] for b in benchmarks),
            "smooth_um": min(smooth) if smooth else None}


def _benchmark(problem, method, powers, resistances):
    return Benchmark(method, problem.rmse_of(resistances),
                     float(powers[problem.weights[:-1] > 0].max()), reversal_rate(problem, powers))


def tracking_bound(scenario, power_cap=None, mode=None, current_A=None, voltage_V=None,
                   preview=False):
    """:class:`TrackingBound` of a :class:`~sma_fmu.cosim.scenario.Scenario`.

    ``power_cap`` P_cap [W] (None: no upper limit) or a whole
    :class:`~.power_limit.PowerLimit`; ``current_A`` I_max [A] and ``voltage_V`` V_max [V]
    (0: none), None: the scenario's ``[drive]`` limits (none by default); ``mode`` overrides
    the hysteresis mode; ``preview`` adds the receding-horizon benchmarks in mode
    "continuous" (minutes).
    """
    start = time.perf_counter()
    problem = TrackingProblem.from_scenario(scenario, mode)
    limit = PowerLimit.of(power_cap, scenario, current_A, voltage_V)
    saturation = saturation_bound(problem)
    if problem.mode == "switch":
        grid = TemperatureGrid.for_problem(problem)
        lower = max(saturation, cell_lower_bound(problem, grid, limit))
        lower_method = f"cell dynamic program, {grid.count} temperature nodes, exact passive cooling"
        _, temperatures, rows = node_path(problem, grid, limit)
        powers, resistances = replay_path(problem, temperatures, rows, limit)
        runs = [(_benchmark(problem, "node dynamic program's path", powers, resistances),
                 powers)]
    else:
        lower, lower_method = saturation, "saturation (reachable band) only"
        runs = []
        for tolerance in TOLERANCES:
            powers, resistances = track(problem, tolerance, limit)
            runs.append((_benchmark(problem, "one-step inverse of the plant" + (
                f", 0 W where a passive step lands within {tolerance:g} ohm" if tolerance else ""),
                powers, resistances), powers))
        for horizon in HORIZONS if preview else ():
            powers, resistances = preview_search(problem, limit, horizon=horizon)
            runs.append((_benchmark(problem, "receding-horizon search with preview, horizon "
                                    f"{horizon} steps", powers, resistances), powers))
    benchmarks = tuple(benchmark for benchmark, _ in runs)
    stroke = (None if problem.stroke_references is None
              else stroke_bound(scenario, problem, runs))
    return TrackingBound(
        scenario=scenario.name, hysteresis_mode=problem.mode, power_cap_W=limit.power_W,
        current_limit_A=limit.current_A, voltage_limit_V=limit.voltage_V,
        saturation_bound_ohm=saturation, lower_bound_ohm=lower, lower_bound_method=lower_method,
        benchmarks=benchmarks, seconds=time.perf_counter() - start, stroke=stroke)
