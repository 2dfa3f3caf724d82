"""Dynamic programs for the "switch" hysteresis mode: a lower bound and an achievable path.

In mode "switch" the plant's whole state is (T, d): R_k is the major branch of direction
d_k at T_k under the load f_(k-1) (spec sections 4, 9, 11). With a power 0 <= P <= P_max
held over a step, T_(k+1) = D(T_k) + G P with D(T) = T_room + a (T - T_room), so any
T_(k+1) in [D(T_k), D(T_k) + G P_max] is reachable, and d_(k+1) = sgn(T_(k+1) - T_k).

**Lower bound** (:func:`cell_lower_bound`): on the cells of a
:class:`~.tracking_problem.TemperatureGrid`, a step moves from cell c to cell c - 1 or c
cooling (passive cooling lands at most one cell down) and to cells c ... c_max(c) heating;
within a cell both directions are allowed. Every true trajectory maps onto such a cell
path, and each (cell, direction) is charged the smallest squared error over its
temperatures, so the optimum over cell paths is <= the error of every power sequence:
a rigorous bound for the model as implemented (to floating-point rounding).

**Achievable** (:func:`node_path`): the same program on the nodes, with only moves a
power in [0, P_max] makes exactly (hold, heat to a node, cool one node at P ~ 0). Its path
is replayed through the runtime plant; the replayed RMSE is what a controller can reach.

**A driver's current or voltage limit** (:class:`~.power_limit.PowerLimit`) makes P_max
depend on the wire's R at the step's start: the lower bound gives each cell the most power
over every resistance the cell holds (both directions, every load of the problem), a
relaxation; the node program gives each node the least over its resistances, so its moves
stay possible; the replay cuts each power to the limit at the plant's own R.
"""
import numpy as np

from sma_fmu.runtime.constant_load import constant_load_resistance
from sma_fmu.runtime.constants import COOLING, HEATING
from sma_fmu.runtime.reachable_band import reachable_band

from .power_limit import PowerLimit

__all__ = ["cell_lower_bound", "node_path", "replay_path"]

_ROWS = (HEATING, COOLING)  # row 0 heating, row 1 cooling
_CHECKPOINT = 1000           # steps between stored value tables of the node program


class _WindowMin:
    """min(values[first[i] ... last[i]]) for fixed index windows; inf where a window is empty."""

    def __init__(self, first, last, size):
        self.size = size
        self.empty = last < first
        self.first = np.minimum(first, size - 1)
        self.to_end = bool(np.all(self.empty | (last >= size - 1)))
        length = np.where(self.empty, 1, last - first + 1)
        level = np.floor(np.log2(length)).astype(np.int64)
        second = np.where(self.empty, self.first, last - (1 << level) + 1)
        self.last = last
        self._table = np.empty((int(level.max()) + 1, size))  # row j: min over 2^j values
        self._left, self._right = level * size + self.first, level * size + second

    def __call__(self, values):
        if self.to_end:  # no power cap: a suffix minimum does
            out = np.minimum.accumulate(values[::-1])[::-1][self.first]
        else:            # sparse table: min of two overlapping power-of-two windows
            table = self._table
            table[0] = values
            for level in range(1, len(table)):
                half = 1 << (level - 1)
                np.minimum(table[level - 1, :-half], table[level - 1, half:], out=table[level, :-half])
                table[level, -half:] = table[level - 1, -half:]
            flat = table.ravel()
            out = np.minimum(flat[self._left], flat[self._right])
        out[self.empty] = np.inf
        return out

    def argmin(self, values, index):
        """Index of the smallest value in window ``index`` (None if empty)."""
        if self.empty[index]:
            return None
        first = self.first[index]
        return first + int(np.argmin(values[first:self.last[index] + 1]))


def _resistances(temperatures, load, direction, params):
    """Major-branch R [ohm] at each temperature [degC] (the runtime's function, element-wise)."""
    return np.array([constant_load_resistance(float(t), load, direction, params)
                     for t in temperatures])


def _squared_distance(value, low, high):
    return np.maximum(low - value, 0.0) ** 2 + np.maximum(value - high, 0.0) ** 2


def _resistance_range(tables):
    """(low, high) [ohm] per cell or node over the R tables given (each (2, size))."""
    stacked = np.concatenate(tables)
    return stacked.min(axis=0), stacked.max(axis=0)


def cell_lower_bound(problem, grid, power_cap=None):
    """Rigorous lower bound on the RMSE [ohm] in mode "switch" (see the module docstring).

    ``power_cap`` P_max [W] or a :class:`~.power_limit.PowerLimit`; None for no upper limit.
    """
    params, limit = problem.params, PowerLimit.of(power_cap)
    low_t, high_t = grid.cell_bounds
    size = grid.count + 2
    charges = {}
    for load in np.unique(problem.sample_loads).tolist():
        hot = reachable_band(load, params).hot
        charges[load] = (
            np.stack([np.append(_resistances(high_t[:-1], load, d, params), hot) for d in _ROWS]),
            np.stack([_resistances(low_t, load, d, params) for d in _ROWS]))
    cap = limit.cap
    if limit.by_resistance:   # the most power over every R a cell holds (a branch is monotone)
        cap = limit.most(*_resistance_range([t for pair in charges.values() for t in pair]))
    reach = problem.after_step(high_t, cap)
    can_heat = problem.after_step(low_t, cap) > low_t  # P_max can still raise T there
    cells = np.arange(size)
    heat = _WindowMin(cells, np.where(can_heat, grid.cell_of(reach), -1), size)
    values = np.zeros((2, size))
    for k in range(problem.steps, -1, -1):
        if k < problem.steps:
            cool = np.minimum(values[1], np.concatenate(([np.inf], values[1, :-1])))
            values = np.broadcast_to(np.minimum(heat(values[0]), cool), (2, size))
        if problem.weights[k]:
            low_r, high_r = charges[float(problem.sample_loads[k])]
            values = values + _squared_distance(problem.references[k], low_r, high_r)
    return problem.rmse(values[0, grid.cell_of(problem.T_start)])


class _NodeProgram:
    """The node program: states (node, row) plus a start node at T_start (index N + 1).

    The path leaves the start in the first step, to any node: under a power cap that move
    may take the plant several steps, which :func:`replay_path` shows (the samples before
    the metric window absorb it in the shipped scenarios).
    """

    def __init__(self, problem, grid, power_cap):
        params, limit = problem.params, PowerLimit.of(power_cap)
        self.problem, self.nodes = problem, grid.nodes
        count = len(self.nodes)
        self.start = count
        self.costs = {}
        for load in np.unique(problem.sample_loads).tolist():
            start_r = constant_load_resistance(problem.T_start, load, HEATING, params)
            self.costs[load] = np.stack([np.append(_resistances(self.nodes, load, d, params), start_r)
                                         for d in _ROWS])
        cap = np.full(count + 1, limit.cap)
        if limit.by_resistance:   # the least power over a node's resistances: always possible
            cap = limit.least(*_resistance_range(list(self.costs.values())))
        self.can_hold = np.append(problem.power_to(self.nodes, self.nodes) <= cap[:count],
                                  problem.power_to(problem.T_start, problem.T_start) <= cap[count])
        reach = problem.after_step(self.nodes, cap[:count])
        self.heat = _WindowMin(np.arange(1, count + 1),
                               np.searchsorted(self.nodes, reach, side="right") - 1, count)

    def cost(self, k):
        problem = self.problem
        if not problem.weights[k]:
            return 0.0
        return (self.costs[float(problem.sample_loads[k])] - problem.references[k]) ** 2

    def back(self, values, k):
        """Values at sample k from those at k + 1."""
        start, hold = self.start, np.where(self.can_hold, values, np.inf)
        heat = self.heat(values[0, :start])
        cool = np.concatenate(([np.inf], values[1, :start - 1]))
        out = np.empty_like(values)
        out[:, :start] = np.minimum(np.minimum(hold[:, :start], heat), cool)
        out[:, start] = values[:, :start].min() if k == 0 else hold[0, start]
        return out + self.cost(k)

    def choose(self, values, state, k):
        """Best successor at sample k + 1 of ``state`` = (node, row) at sample k."""
        node, row = state
        options = []
        if self.can_hold[node] and not (node == self.start and k == 0):
            options.append((values[row, node], state))
        if node == self.start:
            if k > 0:
                return state
            jump_row, jump_node = divmod(int(np.argmin(values[:, :self.start])), self.start)
            options.append((values[jump_row, jump_node], (jump_node, jump_row)))
        else:
            up = self.heat.argmin(values[0, :self.start], node)
            if up is not None:
                options.append((values[0, up], (up, 0)))
            if node >= 1:
                options.append((values[1, node - 1], (node - 1, 1)))
        return min(options, key=lambda option: option[0])[1]


def node_path(problem, grid, power_cap=None):
    """Optimal node path: (value RMSE [ohm], target temperatures [degC], rows), k = 0 ... n.

    rows[k] is 0 (heating) or 1 (cooling): the direction the path holds at sample k.
    """
    program = _NodeProgram(problem, grid, power_cap)
    steps = problem.steps
    values = np.zeros((2, program.start + 1)) + program.cost(steps)
    stored = {steps: values}
    for k in range(steps - 1, -1, -1):
        values = program.back(values, k)
        if k % _CHECKPOINT == 0:
            stored[k] = values
    state, states = (program.start, 0), [(program.start, 0)]
    for first in range(0, steps, _CHECKPOINT):
        last = min(first + _CHECKPOINT, steps)
        tables = {last: stored[last]}
        for k in range(last - 1, first, -1):
            tables[k] = program.back(tables[k + 1], k)
        for k in range(first, last):
            state = program.choose(tables[k + 1], state, k)
            states.append(state)
    temperatures = np.array([problem.T_start if node == program.start else program.nodes[node]
                             for node, _ in states])
    rows = np.array([row for _, row in states])
    return problem.rmse(values[0, program.start]), temperatures, rows


def replay_path(problem, temperatures, rows, power_cap=None):
    """Powers [W] that drive the runtime plant along a temperature path, and its R_k [ohm].

    Each step aims at temperatures[k + 1] with P clamped into [0, P_max] (P_max at the plant's
    R under a current or voltage limit); where the path holds its temperature and the plant
    is on it, the aim is the plant's temperature moved by 1e-9 K in the held direction
    (rows[k + 1]), so the plant keeps that direction.
    """
    limit, plant = PowerLimit.of(power_cap), problem.plant()
    powers = np.empty(problem.steps)
    resistances = np.empty(problem.steps + 1)
    resistances[0] = plant.outputs.R
    for k in range(problem.steps):
        aim = temperatures[k + 1]
        if aim == temperatures[k] and abs(plant.temperature - aim) < 1e-6:
            aim = plant.temperature + (1e-9 if rows[k + 1] == 0 else -1e-9)
        cap = float(limit.at(plant.outputs.R)) if limit.by_resistance else limit.cap
        powers[k] = min(cap, max(0.0, problem.power_to(plant.temperature, aim)))
        resistances[k + 1] = plant.step(float(powers[k]), float(problem.step_loads[k]),
                                        problem.step_s).R
    return powers, resistances
