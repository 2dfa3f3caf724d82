"""The base class of sma-fmu's slaves: a runtime stepper behind pythonfmu's callbacks.

A slave subclasses :class:`StepperSlave`, declares its variables through its
:class:`~.interface.SlaveInterface` in ``__init__``, and provides three methods:

- ``_start()`` -> (stepper, outputs): a new stepper from the present parameters and inputs,
  and the outputs after initialization;
- ``_advance(current_time, step_size)`` -> outputs: one step of the stepper from the inputs;
- ``_publish(outputs)``: copy outputs into the output variables.

``_start`` and ``_advance`` may raise (``ValueError`` naming the parameter or input): the
guard (:class:`~.guards.CallGuard`) turns that into a refused fmi2ExitInitializationMode
or a discarded step. Initialization, guarded steps, the model description's additions and
the saved state (the pythonfmu variables plus the stepper's hidden state) are the same for
every slave, here.
"""
from pythonfmu import Fmi2Slave
from pythonfmu.default_experiment import DefaultExperiment

from sma_fmu.fmi.slave_support.saved_state import split_state, state_with

__all__ = ["StepperSlave"]


class StepperSlave(Fmi2Slave):
    """pythonfmu slave over a runtime stepper (see the module docstring)."""

    # modelDescription.xml attributes every sma-fmu FMU shares (pythonfmu reads the class's)
    author = "sma-fmu"
    default_experiment = DefaultExperiment(start_time=0.0, stop_time=10.0, step_size=1e-3)
    # a step within GRID_TOLERANCE of the first step's size is taken as that size
    # (SlaveInterface.nominal_step); slaves that put their time on the grid themselves say no
    snaps_step = True

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
