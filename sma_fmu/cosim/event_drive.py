"""The PWM driver and the plant in FMI 3.0 event mode: the plant steps from edge to edge.

``run_fmus(..., events=True)`` (``sma-fmu run --fmus DIR --events``) makes every FMU with
``eventModeUsed`` and ``earlyReturnAllowed`` (FMI 3.0 FMUs only). The SmaPwmDriver FMU then
returns early at each edge of its wave, and the master's step k over [t_k, t_k+1) becomes,
from t = t_k:

1. set the driver's ``P_demand`` to the PI's output u_k (held over the whole step, as without
   events), doStep(t, t_k+1 - t): the step ends at t', the first edge inside it, or t_k+1;
2. the driver's ``P_in``, the wave over [t, t') (the peak or 0 W), goes to the plant, which
   steps over [t, t') with it and the load f(t_k);
3. if the driver asked for event handling: fmi3EnterEventMode, fmi3UpdateDiscreteStates
   until nothing changes, fmi3EnterStepMode; then t = t', until t' = t_k+1.

The compensator, the PI and the signals keep the fixed grid. The recorder's rows stay on
that grid (one row per t_k, as without events): row k's ``P`` is the plant's mean applied
power over [t_k, t_k+1) (its energy over the step / h), the plant's columns of row k+1 are
its outputs at t_k+1. What the plant got between the rows is in the optional
``power_trace``: one (start [s], end [s], P_demand [W], P_in [W]) per plant step, which
:func:`traced_driver` also gives for the fixed-step run.
"""

__all__ = ["PassThroughDriver", "EventDrivenPlant", "traced_driver"]


class PassThroughDriver:
    """The loop's driver when the PWM driver sits inside :class:`EventDrivenPlant`: the PI's
    output goes on to the plant as the demand [W]."""

    def step(self, time_s, demand, step_size, resistance=None):
        """``demand`` [W], unchanged (the driver inside the plant applies any limit)."""
        return demand

    def initial(self):
        """0 W (what the PWM driver gives after initialization)."""
        return 0.0


class EventDrivenPlant:
    """The SmaPwmDriver FMU (``driver``, an :class:`~sma_fmu.cosim.master.FmuDriver` with event
    mode) and the plant (an :class:`~sma_fmu.cosim.master.FmuPlant`) stepped together from edge
    to edge; a loop plant whose ``step`` takes the demand [W] instead of the power. The
    master closes the two itself."""

    def __init__(self, driver, plant, power_trace=None):
        self.driver, self.plant = driver, plant
        self._demand = driver.fmu.port(("P_demand",))
        # a limited driver's R input: the wire's resistance at the grid step's start, held
        self._resistance = driver.fmu.port(("R",)) if driver.limited else None
        self._power = driver.fmu.port(("P_in",))
        self.trace = power_trace
        self.steps = 0  # plant steps so far (one or more per grid step)

    def outputs(self):
        """The plant's loop outputs now."""
        return self.plant.outputs()

    def step(self, time_s, demand, load, step_size):
        """Steps of the driver and the plant from edge to edge over [time_s, time_s +
        step_size) with ``demand`` [W] and ``load`` [kg] held; returns the plant's outputs at
        the end, with the applied power as its mean over the step [W]."""
        end = time_s + step_size
        driver, plant_step = self.driver.fmu, self.plant.step
        self._demand.set((demand,))
        if self._resistance is not None:
            self._resistance.set((self.plant.outputs()[0],))
        start, energy = time_s, 0.0
        while True:
            event, early, last = driver.step_events(start, end - start)
            power = self._power.get()[0]
            outputs = plant_step(start, power, load, last - start)
            energy += outputs[6] * (last - start)
            self.steps += 1
            if self.trace is not None:
                self.trace.append((start, last, demand, power))
            if event:
                driver.handle_events()
            if not early:
                break
            start = last
        outputs[6] = energy / step_size
        return outputs


def traced_driver(driver, power_trace):
    """``driver`` whose ``step`` also appends (start [s], end [s], P_demand [W], P_in [W]) to
    ``power_trace``: the fixed-step run's record of what the plant got."""
    step = driver.step

    def traced(time_s, demand, step_size, *resistance):
        power = step(time_s, demand, step_size, *resistance)
        power_trace.append((time_s, time_s + step_size, demand, power))
        return power
    driver.step = traced
    return driver


def period_power_errors(power_trace, frequency_Hz, peak_W, stop_s):
    """Per PWM period j (whole periods before ``stop_s`` [s]): |mean power the plant got over
    [j/f, (j+1)/f) - the duty-cycle value| [W], from a ``power_trace`` (the power held over
    each plant step). The duty-cycle value is peak_W * clip(P_demand / peak_W, 0, 1) for
    the demand held at the period's start (the driver fixes a period's duty there)."""
    import numpy as np

    starts, ends, demands, powers = (np.array(column, dtype=float) for column in zip(*power_trace))
    period = 1.0 / frequency_Hz
    count = int(np.floor(stop_s * frequency_Hz * (1 + 1e-12)))
    errors = np.empty(count)
    for j in range(count):
        begin, finish = j * period, (j + 1) * period
        overlap = np.clip(np.minimum(ends, finish) - np.maximum(starts, begin), 0.0, None)
        mean = float(np.dot(powers, overlap)) / period
        # the step that holds the period's start (within the driver's tolerance, 1e-9 periods)
        first = np.searchsorted(starts, begin + 1e-9 * period, side="right") - 1
        exact = peak_W * min(1.0, max(0.0, demands[first] / peak_W))
        errors[j] = abs(mean - exact)
    return errors
