"""What a validated scenario holds: the :class:`Scenario` record, its controller, drive and
analysis settings, and :class:`ScenarioError`, the error of every scenario problem."""
from collections import namedtuple
from dataclasses import dataclass, field
from pathlib import Path

__all__ = ["ScenarioError", "ControllerSettings", "DriveSettings", "SensorSettings",
           "AnalysisWindow", "Scenario", "CONTROLLERS", "default_analysis"]

CONTROLLERS = ("pi", "pi+ff-fixed", "pi+ff-adaptive")

AnalysisWindow = namedtuple("AnalysisWindow", ["metrics_start_s", "zoom_start_s", "zoom_end_s"])
AnalysisWindow.__doc__ = """Windows of the results [s]: metrics over t >= metrics_start_s; the
comparison figures enlarge zoom_start_s ... zoom_end_s."""


def default_analysis(stop_time_s):
    """The default :class:`AnalysisWindow` of a run lasting ``stop_time_s`` [s].

    The paper's 30-s run gives its choices: metrics over t >= 2 s (the start-up transient
    left out) and an enlarged window of 24-28 s (its Fig. 11). A shorter run scales them:
    metrics from min(2 s, 10 % of the run), the window ending min(2 s, 10 %) before the end
    and lasting min(4 s, 40 %).
    """
    margin = min(2.0, 0.1 * stop_time_s)
    zoom_end = stop_time_s - margin
    return AnalysisWindow(margin, zoom_end - min(4.0, 0.4 * stop_time_s), zoom_end)


class ScenarioError(ValueError):
    """A scenario file or name is wrong; the message names the file, the key and the problem."""


@dataclass(frozen=True)
class ControllerSettings:
    """Controller of a scenario: kind and gains (Kp [W/ohm], Ki [W/(ohm.s)], alpha, beta [s],
    model_load [kg] of the fixed compensator), the compensator's inverse ("major" or
    "minor-loop") and shaping ("none" or "reachable", with the driver's P_max ``power_cap_W``
    [W] or None, and the lower turn's anticipation ``anticipation_s`` [s], 0: none), see :class:`~sma_fmu.runtime.feedforward.FeedforwardStepper`."""

    kind: str
    Kp: float
    Ki: float
    alpha: float
    beta: float
    model_load: float
    inverse: str = "major"
    shaping: str = "none"
    power_cap_W: float = None
    anticipation_s: float = 0.0

    @property
    def feedforward(self):
        """True when the controller uses the compensator."""
        return self.kind != "pi"

    @property
    def adapt_to_load(self):
        """True when the compensator's inverse uses the measured load."""
        return self.kind == "pi+ff-adaptive"


@dataclass(frozen=True)
class DriveSettings:
    """How the loop's power reaches the wire: ``kind`` "power" (the demanded power itself) or
    "pwm" (:class:`~sma_fmu.runtime.pwm.PwmDriver` at ``frequency_Hz`` [Hz] between 0 and
    ``peak_W`` [W]; the plant gets the PWM wave's mean over each step)."""

    kind: str = "power"
    frequency_Hz: float = None
    peak_W: float = None
    # the limits are keyword-only: DriveSettings(kind, frequency_Hz, peak_W) keeps its meaning
    I_max_A: float = field(default=0.0, kw_only=True)   # current limit [A] (0: none), DriveLimit
    V_max_V: float = field(default=0.0, kw_only=True)   # voltage limit [V] (0: none)

    @property
    def pwm(self):
        """True when the power is switched by a PWM driver."""
        return self.kind == "pwm"

    @property
    def limited(self):
        """True when the driver has a current or a voltage limit."""
        return bool(self.I_max_A or self.V_max_V)

    @property
    def driver(self):
        """True when a driver sits between the PI and the plant (PWM, or a limit)."""
        return self.pwm or self.limited


@dataclass(frozen=True)
class SensorSettings:
    """How the controller measures R (:class:`~sma_fmu.runtime.measurement.ResistanceSensor`):
    white noise ``noise_ohm_rms`` [ohm RMS] of stream ``seed``, then a ``bits``-bit ADC over
    0 ... ``full_scale_ohm`` [ohm] (bits 0: no quantisation). The default is ideal (R itself)."""

    noise_ohm_rms: float = 0.0
    full_scale_ohm: float = 0.0
    bits: int = 0
    seed: int = 0

    @property
    def ideal(self):
        """True when the controller reads R exactly (no noise, no quantisation)."""
        return self.noise_ohm_rms == 0.0 and self.bits == 0


@dataclass(frozen=True)
class Scenario:
    """A validated scenario (the file format: :mod:`~sma_fmu.cosim.scenario.reading`)."""

    name: str
    path: Path
    description: str
    stop_time_s: float
    step_s: float
    reference: object
    load: object
    controller: ControllerSettings
    hysteresis_mode: str
    T_start: float
    parameter_set: object
    analysis_window: AnalysisWindow = None   # the file's [analysis]; None: from the duration
    group_name: str = None
    compensator_parameter_set: object = None   # the compensator's model; None: the wire's
    drive: DriveSettings = DriveSettings()     # the file's [drive]; default: power as demanded
    output_interval_s: float = None            # record every k-th step [s]; None: every step
    sensor: SensorSettings = SensorSettings()  # the file's [sensor]; default: R read exactly

    @property
    def params(self):
        """The wire's WireParameters."""
        return self.parameter_set.params

    @property
    def compensator_params(self):
        """The WireParameters of the compensator's inverse model: the wire's, unless a study
        gives the model other values than the wire (``compensator_parameter_set``)."""
        chosen = self.compensator_parameter_set or self.parameter_set
        return chosen.params

    @property
    def steps(self):
        """Number of communication steps n = stop_time / step."""
        return int(round(self.stop_time_s / self.step_s))

    @property
    def analysis(self):
        """The :class:`AnalysisWindow`: the file's ``[analysis]``, or the duration's defaults."""
        return self.analysis_window or default_analysis(self.stop_time_s)

    @property
    def group(self):
        """The comparison group: ``[scenario] group``, or the name up to ``-<controller kind>``.

        Scenarios of one group share a figure and a ranking (e.g. load-step-pi,
        load-step-pi+ff-adaptive and load-step-pi+ff-adaptive-minor-loop: "load-step").
        """
        if self.group_name:
            return self.group_name
        cut = self.name.find("-" + self.controller.kind)
        return self.name[:cut] if cut > 0 else self.name
