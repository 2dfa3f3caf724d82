"""SmaPwmDriver: the PWM wire driver (demanded power in, mean power of the wave out) as an FMI 2.0 CS FMU.

A thin adapter over ``sma_fmu.runtime.pwm.PwmDriver``: a supply switched between
``peak_W`` and 0 W at ``frequency_Hz``, periods starting at t = j / f; at the start of each
period the demanded power sets its duty clip(P_demand / peak_W, 0, 1).

With a current limit ``I_max_A`` or a voltage limit ``V_max_V`` (0: none), the wave's
on-power is peak_W cut to min(I_max^2 R, V_max^2 / R), R the wire's resistance (input R,
from the plant) at the step's start (``sma_fmu.runtime.drive_limit``). ``modulation`` 2
(linear) makes it a linear driver: P_in is P_demand itself within that limit, and
frequency_Hz and peak_W are not used (``modulation``: 1 = pwm, 2 = linear).

Semantics: a sampled block, placed between the PI and the plant. doStep(t, h) holds
P_demand over the step; its output P_in then holds the exact mean of the PWM wave over
[t, t + h), the power the plant's P_in takes for that same step (step it before the
plant: Gauss-Seidel). After initialization (also in Initialization Mode) P_in is 0 W:
no wave has been switched yet. Non-finite P_demand discards the step. Invalid parameters
(frequency_Hz or peak_W not finite and > 0) make exitInitializationMode fail with
fmi2Error naming the reason; the instance stays in Initialization Mode, where they can be
corrected.

Time: like SmaScenarioSignals, the wave is taken on the step grid start + k h_0 (h_0 the
first step's size): a step that starts within a millionth of a step of a grid point and is
h_0 long within as much is [t_k, t_k + h_0) exactly, so a host that adds up its time
(Ecos, OMSimulator) gets the library's wave, not one moved by its rounding errors.
"""
from sma_fmu.fmi.python_family.slave_support.interface import SlaveInterface
from sma_fmu.fmi.python_family.slave_support.stepper_slave import StepperSlave
from sma_fmu.fmi.python_family.slave_support.choices import choice_name
from sma_fmu.runtime.drive_limit import DriveLimit, LinearDriver
from sma_fmu.runtime.pwm import PwmDriver
from sma_fmu.runtime.scenario_signals import grid_point

FREQUENCY_HZ = 50.0   # default switching frequency [Hz]
PEAK_W = 10.0         # default power while on [W]: above what the paper's loops demand


class SmaPwmDriver(StepperSlave):

    description = "PWM driver of the SMA wire: demanded power in, mean power of the PWM wave over the step out"
    snaps_step = False   # puts its time on the step grid itself (see the module docstring)

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.interface = fmi = SlaveInterface(self)
        fmi.input("P_demand", 0.0, "W",
                  "demanded power; sets the duty clip(P_demand / peak_W, 0, 1) of each period at its start")
        fmi.output("P_in", "W", "mean power of the PWM wave over the last step (0 W after initialization)")
        fmi.parameter("frequency_Hz", FREQUENCY_HZ, "Hz",
                      "switching frequency (> 0); periods start at t = j / frequency_Hz")
        fmi.parameter("peak_W", PEAK_W, "W", "power while the switch is on (> 0)")
        fmi.input("R", fmi.defaults.R_P, "ohm",
                  "the wire's resistance (from the plant); read only under a limit")
        fmi.choice_parameter("modulation", "pwm",
                             "pwm: the switched wave; linear: the demand itself, within the limits")
        fmi.parameter("I_max_A", 0.0, "A", "current limit, on-power <= I_max^2 R (0: none)")
        fmi.parameter("V_max_V", 0.0, "V", "voltage limit, on-power <= V_max^2 / R (0: none)")
        self.start_time = 0.0
        self.stepper = None

    def setup_experiment(self, start_time, stop_time, tolerance):
        self.start_time = start_time

    def _start(self):
        limit = DriveLimit(self.I_max_A, self.V_max_V)
        if choice_name("modulation", self.modulation) == "linear":
            return LinearDriver(limit), 0.0
        return PwmDriver(self.frequency_Hz, self.peak_W, limit), 0.0

    def _publish(self, outputs):
        self.P_in = outputs

    def _advance(self, current_time, step_size):
        step = self.interface.nominal_step(step_size)
        start = grid_point(current_time, self.start_time, self.interface.first_step)
        if start is not None and step == self.interface.first_step:
            current_time, step_size = start, step
        return self.stepper.step(self.P_demand, current_time, step_size, self.R)
