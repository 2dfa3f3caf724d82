"""The fmpy co-simulation master: SmaActuator (+ SmaFeedforward, + SmaPwmDriver) FMUs in the closed loop.

Built on fmpy's ``FMU2Slave`` (through :class:`~sma_fmu.fmi.instance.FmuInstance`). The
loop and the PI block are those of :mod:`sma_fmu.cosim.loop`; the compensator FMU is
stepped before the plant (Gauss-Seidel), so u_ff,k reaches the plant's step k. A scenario
with a PWM drive puts the SmaPwmDriver FMU between the PI and the plant, stepped after the
PI and before the plant in the same step: the plant gets the wave's mean over that step.

Each step is one fmi2SetReal, one fmi2DoStep and one fmi2GetReal per FMU (the compensator
also one fmi2GetBoolean), called through ctypes with argument objects built once
(:class:`LeanStep`): no argument conversion per call, values written into and read from
the same C arrays every step. Each block's ``step`` is a closure over those objects (an
instance attribute, built once): no attribute lookup and no call layer per step beyond the
library path's.
"""
import time
from ctypes import c_double, c_int, c_size_t, c_uint, c_void_p
from functools import partial
from pathlib import Path

from sma_fmu.cosim.loop import PLANT_OUTPUTS, LoopResult, run_loop
from sma_fmu.fmi.build import DEFAULT_FMU_DIR, default_fmu_paths, read_description
from sma_fmu.fmi.slave_support.choices import choice_code
from sma_fmu.fmi.instance import FmuError, FmuInstance

__all__ = ["FmuPlant", "FmuCompensator", "FmuDriver", "LeanStep", "needed_fmus", "run_fmus",
           "MissingFmuError", "model_parameter_values"]


class MissingFmuError(FileNotFoundError):
    """A needed FMU has not been built."""


def model_parameter_values(fmu_path, params, variables=None):
    """Start values for every wire parameter the FMU exposes, from ``params``.

    ``variables``: the FMU's model variables if already read (else they are read from
    ``fmu_path``).
    """
    values = params.values()
    variables = read_description(fmu_path).modelVariables if variables is None else variables
    return {v.name: values[v.name] for v in variables
            if v.causality == "parameter" and v.name in values}


class LeanStep:
    """set inputs + doStep + get outputs of one FMU instance, with prebuilt ctypes arguments.

    Parameters
    ----------
    fmu : FmuInstance
        An initialized instance.
    inputs, outputs : tuple of str
        Real inputs set and Real outputs read at every step.
    flags : tuple of str
        Boolean outputs read at every step (one fmi2GetBoolean), or none.
    """

    def __init__(self, fmu, inputs, outputs, flags=()):
        self.fmu = fmu
        component = c_void_p(fmu.component)
        library = fmu.library

        def bound(function, names, ctype):
            references = [fmu.variables[name].valueReference for name in names]
            values = (ctype * len(names))()
            raw = library[function]  # a function object of its own: no argtypes, int result
            raw.restype = c_int
            return partial(raw, component, (c_uint * len(names))(*references),
                           c_size_t(len(names)), values), values

        self._set, self.inputs = bound("fmi2SetReal", inputs, c_double)
        self._get, self.outputs = bound("fmi2GetReal", outputs, c_double)
        self._get_flags, self.flags = bound("fmi2GetBoolean", flags, c_int) if flags else (None, None)
        self._do_step = partial(fmu._do_step_c, component)
        self._names = (inputs, outputs, flags)
        self.step = self._closure()

    def failed(self, stage, status):
        """The :class:`~sma_fmu.fmi.instance.FmuError` of a call above fmi2Warning: ``stage``
        0 set, 1 doStep, 2 get."""
        inputs, outputs, flags = self._names
        what = (f"set {', '.join(inputs)}", "fmi2DoStep", f"get {', '.join(outputs + flags)}")[stage]
        return self.fmu.failure(what, status)

    def _closure(self):
        """:meth:`step` as a closure over the bound calls (the blocks below inline the same
        calls in their own closures)."""
        set_, do_step, get, get_flags, failed = (self._set, self._do_step, self._get,
                                                 self._get_flags, self.failed)

        def step(time_s, step_size):
            """Set :attr:`inputs` (write them first), doStep, read :attr:`outputs` (and
            :attr:`flags`); raises :class:`~sma_fmu.fmi.instance.FmuError` above fmi2Warning."""
            status = set_()
            if status > 1:
                raise failed(0, status)
            status = do_step(time_s, step_size, 1)
            if status > 1:
                raise failed(1, status)
            status = get()
            if status <= 1 and get_flags is not None:
                status = get_flags()
            if status > 1:
                raise failed(2, status)
        return step


class FmuPlant:
    """The SmaActuator FMU as a loop plant."""

    def __init__(self, scenario, fmu_path, instance_name="plant"):
        start = model_parameter_values(fmu_path, scenario.params)
        start.update(T_start=scenario.T_start,
                     hysteresis_mode=choice_code("hysteresis_mode", scenario.hysteresis_mode),
                     load=scenario.load.value(0.0))
        self.fmu = FmuInstance(fmu_path, instance_name, start)
        self._outputs = self.fmu.port(PLANT_OUTPUTS)
        lean = LeanStep(self.fmu, ("P_in", "load"), PLANT_OUTPUTS)
        inputs, values = lean.inputs, lean.outputs
        set_, do_step, get, failed = lean._set, lean._do_step, lean._get, lean.failed

        def step(time_s, power, load, step_size):
            """Set P_in and load, doStep, return the PLANT_OUTPUTS at the end of the step."""
            inputs[0] = power
            inputs[1] = load
            status = set_()
            if status > 1:
                raise failed(0, status)
            status = do_step(time_s, step_size, 1)
            if status > 1:
                raise failed(1, status)
            status = get()
            if status > 1:
                raise failed(2, status)
            return values[:]
        self.step = step

    def outputs(self):
        """The loop's :data:`~sma_fmu.cosim.loop.PLANT_OUTPUTS` now."""
        return self._outputs.get()

    def close(self):
        """Free the instance."""
        self.fmu.close()


class FmuCompensator:
    """The SmaFeedforward FMU as the loop's compensator."""

    def __init__(self, scenario, fmu_path, instance_name="feedforward"):
        c = scenario.controller
        start = model_parameter_values(fmu_path, scenario.compensator_params)
        start.update(alpha=c.alpha, beta=c.beta, model_load=c.model_load,
                     adapt_to_load=c.adapt_to_load, inverse=choice_code("inverse", c.inverse),
                     R_ref=scenario.reference.value(0.0),
                     load=scenario.load.value(0.0))
        self.fmu = FmuInstance(fmu_path, instance_name, start)
        lean = LeanStep(self.fmu, ("R_ref", "load"), ("P_ff", "T_ref"), ("saturated",))
        inputs, outputs, saturated = lean.inputs, lean.outputs, lean.flags
        set_, do_step, get, get_flags, failed = (lean._set, lean._do_step, lean._get,
                                                 lean._get_flags, lean.failed)

        def step(time_s, reference, load, step_size):
            """Set R_ref and load, doStep, return (P_ff, T_ref, saturated) for this sample."""
            inputs[0] = reference
            inputs[1] = load
            status = set_()
            if status > 1:
                raise failed(0, status)
            status = do_step(time_s, step_size, 1)
            if status > 1:
                raise failed(1, status)
            status = get()
            if status <= 1:
                status = get_flags()
            if status > 1:
                raise failed(2, status)
            return outputs[0], outputs[1], saturated[0] != 0
        self.step = step

    def close(self):
        """Free the instance."""
        self.fmu.close()


class FmuDriver:
    """The SmaPwmDriver FMU as the loop's driver (the hook of :func:`~sma_fmu.cosim.loop.run_loop`)."""

    def __init__(self, scenario, fmu_path, instance_name="driver"):
        drive = scenario.drive
        self.fmu = FmuInstance(fmu_path, instance_name,
                               {"frequency_Hz": drive.frequency_Hz, "peak_W": drive.peak_W})
        self._initial = self.fmu.port(("P_in",))
        lean = LeanStep(self.fmu, ("P_demand",), ("P_in",))
        inputs, outputs, lean_step = lean.inputs, lean.outputs, lean.step

        def step(time_s, demand, step_size):
            """Set P_demand [W], doStep, return P_in [W]: the wave's mean over the step."""
            inputs[0] = demand
            lean_step(time_s, step_size)
            return outputs[0]
        self.step = step

    def initial(self):
        """P_in [W] after initialization, before the first step (0 W)."""
        return self._initial.get()[0]

    def close(self):
        """Free the instance."""
        self.fmu.close()


def needed_fmus(scenario):
    """Names of the FMUs the FMU path of ``scenario`` runs: the plant, and the compensator
    and the PWM driver when the scenario has them."""
    return (["SmaActuator"] + (["SmaFeedforward"] if scenario.controller.feedforward else [])
            + (["SmaPwmDriver"] if scenario.drive.pwm else []))


def run_fmus(scenario, fmu_dir=DEFAULT_FMU_DIR, sink=None):
    """Run ``scenario`` through the FMUs in ``fmu_dir``; returns a :class:`LoopResult`.

    ``sink``: see :func:`~sma_fmu.cosim.loop.run_loop` (then the result's ``data`` is None).
    """
    paths = default_fmu_paths(fmu_dir)
    for name in needed_fmus(scenario):
        if not paths[name].is_file():
            raise MissingFmuError(f"{paths[name]} not found; build the FMUs first: "
                                  f"sma-fmu build --out {Path(fmu_dir)}")
    start = time.perf_counter()
    parts = {}
    try:
        parts["plant"] = FmuPlant(scenario, paths["SmaActuator"])
        if scenario.controller.feedforward:
            parts["compensator"] = FmuCompensator(scenario, paths["SmaFeedforward"])
        if scenario.drive.pwm:
            parts["driver"] = FmuDriver(scenario, paths["SmaPwmDriver"])
        data = run_loop(scenario, parts["plant"], parts.get("compensator"),
                        driver=parts.get("driver"), sink=sink)
    except FmuError as error:
        raise FmuError(f"scenario {scenario.name}: {error}", error.status) from None
    finally:
        for part in parts.values():
            part.close()
    return LoopResult(scenario, data, "fmu", time.perf_counter() - start)
