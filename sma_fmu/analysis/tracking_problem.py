"""A tracking problem as arrays: the reference, the loads, the metric window, and a replay.

The problem is the co-simulation of spec section 11 with the controller taken out: the
plant (:class:`~sma_fmu.runtime.plant.PlantStepper`) is stepped from t_k to t_k+1 with a
power P_k >= 0 [W] and the load f(t_k) held; R_k is evaluated with the load of the step
that ended at t_k. The cost is the metric of :mod:`sma_fmu.cosim.metrics`: the RMSE of
e_k = R_k - R_ref(t_k) over the samples with t_k >= the scenario's metrics start (2 s in
the paper's runs).

:class:`TemperatureGrid` is the grid of the dynamic programs: T_i = T_room + d0 e^(i delta)
with delta a hair above h/tau_th, so one step at P = 0 takes node i to just above node i-1
(exact passive cooling lands at most one cell down, and a tiny P >= 0 lands on node i-1).
"""
import math
from dataclasses import dataclass

import numpy as np

from sma_fmu.runtime.plant import PlantStepper
from sma_fmu.runtime.signals import is_stroke
from sma_fmu.runtime.thermal import step_decay, thermal_step

__all__ = ["TrackingProblem", "TemperatureGrid"]


@dataclass(frozen=True)
class TrackingProblem:
    """One scenario's tracking task (arrays indexed by the sample k = 0 ... n).

    references : R_ref(t_k) [ohm], n + 1 values;
    step_loads : f(t_k) held over step k [kg], n values;
    sample_loads : load R_k is evaluated with [kg] (f(0) for k = 0, else step_loads[k-1]);
    weights : 1 where t_k is in the metric window, else 0;
    stroke_references : a stroke reference's stroke(t_k) [m] (None: R_ref is the reference).
    """

    name: str
    params: object
    mode: str
    step_s: float
    T_start: float
    references: np.ndarray
    step_loads: np.ndarray
    sample_loads: np.ndarray
    weights: np.ndarray
    stroke_references: np.ndarray = None

    @classmethod
    def from_scenario(cls, scenario, mode=None):
        """The problem of a :class:`~sma_fmu.cosim.scenario.Scenario` (``mode`` overrides its hysteresis mode)."""
        h, n = scenario.step_s, scenario.steps
        times = np.arange(n + 1) * h
        loads = np.array([scenario.load.value(t) for t in times])
        return cls(
            name=scenario.name, params=scenario.params,
            mode=scenario.hysteresis_mode if mode is None else mode,
            step_s=h, T_start=scenario.T_start,
            references=np.array([scenario.reference.value(t) for t in times]),
            step_loads=loads[:-1], sample_loads=np.concatenate((loads[:1], loads[:-1])),
            weights=(times >= scenario.analysis.metrics_start_s - 1e-9 * h).astype(float),
            stroke_references=None if not is_stroke(scenario.reference)
            else np.array([scenario.reference.stroke(t) for t in times]))

    @property
    def steps(self):
        """Number of steps n."""
        return len(self.step_loads)

    @property
    def decay(self):
        """a = exp(-h/tau_th) [1]: one passive step maps T - T_room to a (T - T_room)."""
        return step_decay(self.step_s, self.params.tau_th)

    @property
    def heating_gain(self):
        """G = K_th (1 - a) [K/W]: the temperature one step adds per watt held."""
        return self.params.K_th * (1.0 - self.decay)

    def after_step(self, temperature, power):
        """Temperature [degC] one step after ``temperature`` [degC] at ``power`` [W] (arrays too).

        The runtime's exact thermal step (:func:`~sma_fmu.runtime.thermal.thermal_step`).
        """
        params = self.params
        return thermal_step(temperature, power, params.T_room, params.K_th, self.decay)

    def power_to(self, temperature, target):
        """Power [W] that takes ``temperature`` to ``target`` [degC] in one step (may be < 0).

        The inverse of :meth:`after_step`, which is linear in the power.
        """
        return (target - self.after_step(temperature, 0.0)) / self.heating_gain

    def rmse(self, squared_sum):
        """RMSE [ohm] from a weighted sum of squared errors [ohm^2]."""
        return math.sqrt(max(float(squared_sum), 0.0) / self.weights.sum())

    def rmse_of(self, resistances):
        """RMSE [ohm] of the samples R_k [ohm] against the reference, over the metric window."""
        error = np.asarray(resistances) - self.references
        return self.rmse(np.sum(self.weights * error * error))

    def stroke_rmse_um(self, strokes):
        """RMSE [um] of the strokes x_0 - x_k [m] against the stroke reference, metric window."""
        error = np.asarray(strokes) - self.stroke_references
        return 1e6 * self.rmse(np.sum(self.weights * error * error))

    def replay_strokes(self, powers):
        """Strokes x_0 - x_k [m], k = 0 ... n, of ``powers`` [W] through a fresh plant."""
        plant = self.plant()
        start = plant.outputs.x
        lengths = [start]
        step, h = plant.step, self.step_s
        for power, load in zip(powers.tolist(), self.step_loads.tolist()):
            lengths.append(step(power, load, h).x)
        return start - np.array(lengths)

    def plant(self):
        """A fresh runtime plant at the problem's start (T_start, heating, major branch)."""
        return PlantStepper(self.params, self.T_start, self.mode, float(self.sample_loads[0]))

    def replay(self, powers):
        """R_k [ohm], k = 0 ... n, of the power sequence ``powers`` [W] through a fresh plant."""
        plant = self.plant()
        resistances = np.empty(self.steps + 1)
        resistances[0] = plant.outputs.R
        step, h = plant.step, self.step_s
        for k, (power, load) in enumerate(zip(powers.tolist(), self.step_loads.tolist())):
            resistances[k + 1] = step(power, load, h).R
        return resistances


@dataclass(frozen=True)
class TemperatureGrid:
    """Nodes T_i = T_room + d0 e^(i delta) [degC], i = 0 ... N, and the cells between them.

    Cell 0 is [T_bottom, T_0), cell i is [T_(i-1), T_i) for i = 1 ... N, and cell N + 1 is
    [T_N, inf). ``delta`` = (h/tau_th)(1 + 1e-9): a passive step from a cell lands in that
    cell or the one below, with a margin (~1e-10 K) far above rounding.
    """

    T_room: float
    T_bottom: float
    offset: float
    delta: float
    count: int

    @classmethod
    def for_problem(cls, problem, low=20.0, high=125.0):
        """A grid from T_room + ``low`` to at least T_room + ``high`` [K above room].

        The defaults give 30-135 degC for the reference wire (10 degC room): below, the
        wire is fully cold; above, fully hot (the top cell holds both ends' rest anyway).
        """
        params = problem.params
        delta = problem.step_s / params.tau_th * (1.0 + 1e-9)
        offset = low
        count = int(math.ceil(math.log(high / offset) / delta))
        return cls(params.T_room, min(params.T_room, problem.T_start), offset, delta, count)

    @property
    def nodes(self):
        """T_i [degC], i = 0 ... N."""
        return self.T_room + self.offset * np.exp(self.delta * np.arange(self.count + 1))

    @property
    def cell_bounds(self):
        """(low, high) [degC] of the cells 0 ... N + 1 (high of the top cell is inf)."""
        nodes = self.nodes
        return (np.concatenate(([self.T_bottom], nodes)), np.concatenate((nodes, [np.inf])))

    def cell_of(self, temperatures):
        """Index of the cell holding each temperature [degC] (>= T_bottom)."""
        return np.searchsorted(self.nodes, temperatures, side="right")
