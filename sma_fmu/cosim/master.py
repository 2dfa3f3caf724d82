"""The fmpy co-simulation master: SmaActuator (+ SmaFeedforward, + SmaPwmDriver) FMUs in the closed loop.

Built on fmpy's ``FMU2Slave`` (through :class:`~sma_fmu.fmi.driving.instance.FmuInstance`). The
loop and the PI block are those of :mod:`sma_fmu.cosim.loop`; the compensator FMU is
stepped before the plant (Gauss-Seidel), so u_ff,k reaches the plant's step k. A scenario
with a PWM drive puts the SmaPwmDriver FMU between the PI and the plant, stepped after the
PI and before the plant in the same step: the plant gets the wave's mean over that step.
Which FMUs a scenario needs and their start values are the loop system's
(:func:`~sma_fmu.fmi.loop.system.loop_system`), as for the C master and the system tools.
A stroke reference is mapped to R_ref at every step before the loop, in C as the C master
does (:mod:`sma_fmu.cosim.stroke_table`), or in Python step by step where no C compiler is:
the same values.

Each step is one fmi2SetReal, one fmi2DoStep and one fmi2GetReal per FMU (the compensator
also one fmi2GetBoolean), called through ctypes with argument objects built once
(:class:`LeanStep`): no argument conversion per call, values written into and read from
the same C arrays every step. An FMU with sma-fmu's C front also exports
``sma_fmu_step`` (``fmi/python_family/front/combined_step.c``): those same calls made in C, in one
ctypes call instead of three or four; LeanStep uses it when it is there. Each block's
``step`` is a closure over those objects (an instance attribute, built once): no attribute
lookup per step.
"""
import time
from ctypes import POINTER, Structure, byref, c_double, c_int, c_size_t, c_uint, c_void_p, sizeof
from functools import partial

from sma_fmu.cosim.event_drive import EventDrivenPlant, PassThroughDriver, traced_driver
from sma_fmu.cosim.loop import PLANT_OUTPUTS, LoopResult, run_loop
from sma_fmu.cosim.run_warnings import WarningTexts, model_text, ordered
from sma_fmu.cosim.stroke_table import available_program, stroke_reference_at
from sma_fmu.fmi.driving.instance import FmuError
from sma_fmu.fmi.driving.instance3 import open_instance
from sma_fmu.fmi.loop.system import loop_system
from sma_fmu.fmi.packaging.fmu_names import DEFAULT_FMU_DIR, default_fmu_paths
from sma_fmu.runtime.signals import is_stroke

__all__ = ["FMU_BLOCKS", "FmuPlant", "FmuCompensator", "FmuDriver", "LeanStep", "run_fmus"]

# the loop's components this master runs as FMUs (the PI and the signals are Python's: the
# PI of :func:`~sma_fmu.cosim.loop.run_loop`, the scenario's signals)
FMU_BLOCKS = ("compensator", "driver", "plant")


class SmaFmuStep(Structure):
    """The argument of the front's ``sma_fmu_step`` (``fmi/python_family/front/combined_step.c``)."""

    _fields_ = [("size", c_size_t), ("component", c_void_p),
                ("input_vr", POINTER(c_uint)), ("n_inputs", c_size_t), ("inputs", POINTER(c_double)),
                ("output_vr", POINTER(c_uint)), ("n_outputs", c_size_t), ("outputs", POINTER(c_double)),
                ("flag_vr", POINTER(c_uint)), ("n_flags", c_size_t), ("flags", POINTER(c_int)),
                ("t", c_double), ("h", c_double), ("stage", c_int)]


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
    combined : bool or None
        Make the calls through the FMU's ``sma_fmu_step`` export (one ctypes call): None
        if it has one, False never (the separate FMI calls).
    """

    def __init__(self, fmu, inputs, outputs, flags=(), combined=None):
        self.fmu = fmu
        component = c_void_p(fmu.component)
        library = fmu.library
        self._names = (inputs, outputs, flags)
        real, boolean = fmu.PORT_TYPES  # (FMI 2.0: Real, Boolean; FMI 3.0: Float64, Boolean)

        def bound(kind, getter, names):
            _, set_name, get_name, ctype = fmu.ACCESSORS[kind]
            references = (c_uint * len(names))(*(fmu.variables[name].valueReference for name in names))
            values = (ctype * len(names))()
            raw = library[get_name if getter else set_name]  # a function object of its own: no argtypes
            raw.restype = c_int
            return fmu.bind(raw, references, values), values

        self._set, self.inputs = bound(real, False, inputs)
        self._get, self.outputs = bound(real, True, outputs)
        self._get_flags, self.flags = bound(boolean, True, flags) if flags else (None, None)
        self._do_step = fmu.step_call()
        self.combined = None
        if combined is not False:
            self.combined = self._combined_call(library, component)
        self.step = self._closure()

    def _combined_call(self, library, component):
        """(call, arguments): ``sma_fmu_step`` bound to its :class:`SmaFmuStep`, filled
        but for t and h; None if the library has no such export."""
        try:
            raw = library["sma_fmu_step"]
        except AttributeError:  # not an FMU with sma-fmu's front
            return None
        raw.restype = c_int

        def bound(call):  # (references, count, values) of a bound set/get, or none
            return call.args[1:4] if call is not None else (None, c_size_t(0), None)
        fields = [value for call in (self._set, self._get, self._get_flags) for value in bound(call)]
        # (the arrays it points into stay alive with the bound calls above)
        arguments = SmaFmuStep(sizeof(SmaFmuStep), component, *fields)
        return partial(raw, byref(arguments)), arguments

    def failed(self, stage, status):
        """The :class:`~sma_fmu.fmi.driving.instance.FmuError` of a call above fmi2Warning: ``stage``
        0 set, 1 doStep, 2 get."""
        inputs, outputs, flags = self._names
        what = (f"set {', '.join(inputs)}", f"{self.fmu.PREFIX}DoStep",
                f"get {', '.join(outputs + flags)}")[min(stage, 2)]
        return self.fmu.failure(what, status)

    def _closure(self):
        """:meth:`step` as a closure over the bound calls."""
        failed = self.failed
        if self.combined is not None:
            call, arguments = self.combined

            def step(time_s, step_size):
                """Set :attr:`inputs` (write them first), doStep, read :attr:`outputs` (and
                :attr:`flags`), in one call; raises :class:`~sma_fmu.fmi.driving.instance.FmuError`
                above fmi2Warning."""
                arguments.t = time_s
                arguments.h = step_size
                status = call()
                if status > 1:
                    raise failed(arguments.stage, status)
            return step
        set_, do_step, get, get_flags = self._set, self._do_step, self._get, self._get_flags

        def step(time_s, step_size):
            """Set :attr:`inputs` (write them first), doStep, read :attr:`outputs` (and
            :attr:`flags`); raises :class:`~sma_fmu.fmi.driving.instance.FmuError` above fmi2Warning."""
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


def _starts(component):
    """The start values of ``component`` (a :class:`~sma_fmu.fmi.loop.system.Component`):
    its parameters, then its inputs at t = 0 (this master sets the inputs itself)."""
    return {**component.parameters, **component.input_starts}


class FmuPlant:
    """The SmaActuator FMU (``component`` "plant" of the loop system) as a loop plant."""

    def __init__(self, component, instance_name="plant", combined=None, events=False):
        self.fmu = open_instance(component.fmu, instance_name, _starts(component), events=events)
        self._outputs = self.fmu.port(PLANT_OUTPUTS)
        lean = LeanStep(self.fmu, ("P_in", "load"), PLANT_OUTPUTS, combined=combined)
        inputs, values, lean_step = lean.inputs, lean.outputs, lean.step

        def step(time_s, power, load, step_size):
            """Set P_in and load, doStep, return the PLANT_OUTPUTS at the end of the step."""
            inputs[0] = power
            inputs[1] = load
            lean_step(time_s, step_size)
            return values[:]
        self.step = step

    def outputs(self):
        """The loop's :data:`~sma_fmu.cosim.loop.PLANT_OUTPUTS` now."""
        return self._outputs.get()

    def close(self):
        """Free the instance."""
        self.fmu.close()


class FmuCompensator:
    """The SmaFeedforward FMU (``component`` "compensator") as the loop's compensator."""

    def __init__(self, component, instance_name="feedforward", combined=None, events=False):
        self.fmu = open_instance(component.fmu, instance_name, _starts(component), events=events)
        lean = LeanStep(self.fmu, ("R_ref", "load"), ("P_ff", "T_ref"), ("saturated",),
                        combined=combined)
        inputs, outputs, saturated, lean_step = lean.inputs, lean.outputs, lean.flags, lean.step

        def step(time_s, reference, load, step_size):
            """Set R_ref and load, doStep, return (P_ff, T_ref, saturated) for this sample."""
            inputs[0] = reference
            inputs[1] = load
            lean_step(time_s, step_size)
            return outputs[0], outputs[1], saturated[0] != 0
        self.step = step

    def close(self):
        """Free the instance."""
        self.fmu.close()


class FmuDriver:
    """The SmaPwmDriver FMU (``component`` "driver") as the loop's driver (the hook of
    :func:`~sma_fmu.cosim.loop.run_loop`). ``limited``: the driver has a current or voltage
    limit, so its R input gets the wire's resistance at each step's start."""

    def __init__(self, component, instance_name="driver", combined=None, events=False,
                 limited=False):
        self.fmu = open_instance(component.fmu, instance_name, _starts(component), events=events)
        self.limited = limited
        self._initial = self.fmu.port(("P_in",))
        lean = LeanStep(self.fmu, ("P_demand", "R") if limited else ("P_demand",), ("P_in",),
                        combined=combined)
        inputs, outputs, lean_step = lean.inputs, lean.outputs, lean.step

        def step(time_s, demand, step_size, resistance=None):
            """Set P_demand [W] (and R [ohm]), doStep, return P_in [W]: the wave's mean over
            the step, or the demand within the limit."""
            inputs[0] = demand
            if limited:
                inputs[1] = resistance
            lean_step(time_s, step_size)
            return outputs[0]
        self.step = step

    def initial(self):
        """P_in [W] after initialization, before the first step (0 W)."""
        return self._initial.get()[0]

    def close(self):
        """Free the instance."""
        self.fmu.close()


def run_fmus(scenario, fmu_dir=DEFAULT_FMU_DIR, sink=None, combined=None, events=False,
             power_trace=None):
    """Run ``scenario`` through the FMUs in ``fmu_dir``; returns a :class:`LoopResult`.

    Each FMU is driven through the adapter of its own FMI version (2.0 or 3.0; a folder may
    mix them). ``sink``: see :func:`~sma_fmu.cosim.loop.run_loop` (then the result's
    ``data`` is None). ``combined``: see :class:`LeanStep` (False: the separate FMI calls).
    ``events``: FMI 3.0 event mode and early return (:mod:`sma_fmu.cosim.event_drive`);
    every FMU the scenario needs must be FMI 3.0 (``ValueError`` names one that is not).
    ``power_trace``: a list that gets (start [s], end [s], P_demand [W], P_in [W]) of every
    step the plant makes behind the PWM driver (scenarios with ``[drive] kind = "pwm"``).
    """
    system = loop_system(scenario, default_fmu_paths(fmu_dir), only=FMU_BLOCKS)
    if events:
        older = [c for c in system.components if c.fmi_version != "3"]
        if older:
            raise ValueError(f"--events: {older[0].fmu} is an FMI {older[0].fmi_version}.0 FMU; "
                             f"event mode and early return need FMI 3.0 FMUs (sma-fmu build "
                             f"--native --fmi 3)")
    start = time.perf_counter()
    # a stroke reference mapped in C at every step when a compiler is there (one process
    # for the run, not a search per step in Python), else by the Python map: the same R_ref
    reference_at = (stroke_reference_at(scenario, available_program()) if is_stroke(scenario.reference)
                    else None)
    parts = {}
    try:
        parts["plant"] = FmuPlant(system.component("plant"), combined=combined, events=events)
        if scenario.controller.feedforward:
            parts["compensator"] = FmuCompensator(system.component("compensator"),
                                                  combined=combined, events=events)
        if scenario.drive.driver:
            parts["driver"] = FmuDriver(system.component("driver"), combined=combined,
                                        events=events, limited=scenario.drive.limited)
        plant, driver = parts["plant"], parts.get("driver")
        if events and driver is not None:
            plant, driver = EventDrivenPlant(driver, plant, power_trace), PassThroughDriver()
        elif driver is not None and power_trace is not None:
            driver = traced_driver(driver, power_trace)
        data = run_loop(scenario, plant, parts.get("compensator"), driver=driver, sink=sink,
                        reference_at=reference_at)
        warnings = _logged_warnings(parts)
    except FmuError as error:
        raise FmuError(f"scenario {scenario.name}: {error}", error.status) from None
    finally:
        for part in parts.values():
            part.close()
    return LoopResult(scenario, data, "fmu", time.perf_counter() - start, warnings)


def _logged_warnings(parts):
    """The warnings the FMUs of ``parts`` ({component: FmuPlant, ...}) logged, in the
    runtime's text (:mod:`sma_fmu.cosim.run_warnings`): read from the messages each
    instance's logger kept, after the run (nothing per step)."""
    found = {}
    for name, part in parts.items():
        texts = found[name] = WarningTexts()
        for status, message in part.fmu.messages:
            if status == "warning":
                texts.add(model_text(message))
    return ordered(found)
