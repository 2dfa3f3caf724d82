"""The base class of sma-fmu's slaves: a runtime stepper behind pythonfmu's callbacks.

A slave subclasses :class:`StepperSlave`, declares its variables through its
:class:`~.interface.SlaveInterface` in ``__init__``, and provides three methods:

- ``_start()`` -> (stepper, outputs): a new stepper from the present parameters and inputs,
  and the outputs after initialization;
- ``_advance(current_time, step_size)`` -> outputs: one step of the stepper from the inputs;
- ``_publish(outputs)``: copy outputs into the output variables.

Most slaves declare the last two instead of writing them: ``published`` (the variables the
stepper's outputs go to, in order) and ``step_inputs`` (the variables passed to
``stepper.<step_method>(..., step_size)``); the methods are then compiled from the names
(:mod:`.compiled`), and the front's direct step inlines the same call (:mod:`.direct_step`).

``_start`` and ``_advance`` may raise (``ValueError`` naming the parameter or input): the
guard (:class:`~.guards.CallGuard`) turns that into a refused fmi2ExitInitializationMode
or a discarded step. Initialization, guarded steps, the model description's additions and
the saved state (the pythonfmu variables plus the stepper's hidden state) are the same for
every slave, here.
"""
from pythonfmu import Fmi2Slave
from pythonfmu.default_experiment import DefaultExperiment

from sma_fmu.fmi.python_family.slave_support.compiled import attribute_writer, stepper_call
from sma_fmu.fmi.python_family.slave_support.saved_state import split_state, state_with

__all__ = ["StepperSlave"]


class StepperSlave(Fmi2Slave):
    """pythonfmu slave over a runtime stepper (see the module docstring)."""

    # modelDescription.xml attributes every sma-fmu FMU shares (pythonfmu reads the class's)
    author = "sma-fmu"
    default_experiment = DefaultExperiment(start_time=0.0, stop_time=10.0, step_size=1e-3)
    # a step within GRID_TOLERANCE of the first step's size is taken as that size
    # (SlaveInterface.nominal_step); slaves that put their time on the grid themselves say no
    snaps_step = True
    # declared instead of _publish / _advance (see the module docstring); None: written
    published = None      # names of the variables the outputs go to, in the outputs' order
    step_inputs = None    # names of the variables stepper.<step_method> takes before step_size
    step_method = "step"

    # (method, step_inputs, published, snaps_step) when do_step is this class's and _advance
    # and _publish are the declared ones: the front's direct step may inline them
    declared_step = None

    def __init_subclass__(cls, **kwargs):
        super().__init_subclass__(**kwargs)
        if "published" in cls.__dict__ and cls.published is not None:
            cls._publish = attribute_writer(cls.published)
            cls._publish.declared = tuple(cls.published)
        if "step_inputs" in cls.__dict__ and cls.step_inputs is not None:
            cls._advance = stepper_call(cls.step_method, cls.step_inputs)
            cls._advance.declared = (cls.step_method, tuple(cls.step_inputs))
        declared = (cls.published is not None and cls.step_inputs is not None and
                    cls.do_step is StepperSlave.do_step and
                    getattr(cls._publish, "declared", None) == tuple(cls.published) and
                    getattr(cls._advance, "declared", None) == (cls.step_method, tuple(cls.step_inputs)))
        cls.declared_step = (cls.step_method, tuple(cls.step_inputs), tuple(cls.published),
                             bool(cls.snaps_step)) if declared else None

    def exit_initialization_mode(self):
        self.stepper = None  # a failed start leaves none (and a saved state says so)
        self.stepper, outputs = self._start()
        self._publish(outputs)

    def do_step(self, current_time, step_size):
        if self.snaps_step:
            interface = self.interface
            if step_size != interface.first_step:  # (equal: nominal_step gives it back)
                step_size = interface.nominal_step(step_size)
        self._publish(self._advance(current_time, step_size))
        return True

    def to_xml(self, model_options=None):
        return self.interface.decorate(super().to_xml({} if model_options is None else model_options))

    def _get_fmu_state(self):
        return state_with(super()._get_fmu_state(), self.stepper)

    def _set_fmu_state(self, state):
        variables, stepper_state = split_state(state)
        super()._set_fmu_state(variables)
        # a new stepper with the restored parameters, then its hidden state
        self.stepper = None if stepper_state is None else self._start()[0]
        if self.stepper is not None:
            self.stepper.restore(stepper_state)
            outputs = getattr(self.stepper, "outputs", None)
            if outputs is not None:  # steppers that hold their outputs (the others' are variables)
                self._publish(outputs)
                self._check_held_outputs(variables)

    def _check_held_outputs(self, variables):
        """The saved outputs must be those the restored stepper gave (an edited output is
        refused like an edited entry: ValueError naming it, its unit and the value)."""
        units = self.interface.units
        for name in self.published or ():
            given, value = variables.get(name), getattr(self, name)
            if given != value:
                unit = f" {units[name]}" if units.get(name, "1") != "1" else ""
                raise ValueError(f"output {name} = {given!r}{unit} is not what the saved model "
                                 f"state gives ({value!r}{unit})")
