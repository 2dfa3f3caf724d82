"""SmaScenarioSignals replays a restored state on the saved run's time grid (found with
fmusim v0.0.39, which resumes a run from a serialized state: docs/systems.md, "FMI 3.0 hosts
built by hand").

The source samples t + h on the grid start + k h0, h0 the run's first step. A restored
source took h0 from the next step instead, and a host that steps from t to t_next passes
t_next - t, a rounding error off h (1.001 - 1 = 0.00099999999999989): after 1000 such steps
the grid lay 1e-13 s off and R_ref 3.2e-12 ohm off the run that was saved. Here one instance
steps 1 s at h, saves its state, takes 1000 steps as such a host does, restores the state and
takes the same 1000 steps again: both passes must be equal, in each family and version."""
import pytest
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave
from fmpy.fmi3 import FMU3Slave

H = 1e-3


def _two_passes(path):
    description = read_model_description(str(path))
    reference = next(v.valueReference for v in description.modelVariables if v.name == "R_ref")
    kind = FMU3Slave if description.fmiVersion.startswith("3") else FMU2Slave
    fmu = kind(guid=description.guid, unzipDirectory=extract(str(path)),
               modelIdentifier=description.coSimulation.modelIdentifier, instanceName="grid")
    fmu.instantiate()
    if kind is FMU3Slave:
        fmu.enterInitializationMode(startTime=0.0)
        read = lambda: fmu.getFloat64([reference])[0]  # noqa: E731
    else:
        fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
        read = lambda: fmu.getReal([reference])[0]  # noqa: E731
    fmu.exitInitializationMode()
    try:
        for k in range(1000):
            fmu.doStep(k * H, H)
        state = fmu.getFMUState()

        def steps():
            values = []
            for k in range(1000):
                start, end = 1.0 + k * H, 1.0 + (k + 1) * H
                fmu.doStep(start, end - start)
                values.append(read())
            return values

        first = steps()
        fmu.setFMUState(state)
        return first, steps()
    finally:
        fmu.terminate()
        fmu.freeInstance()


@pytest.fixture(scope="module")
def fmi3_signals(tmp_path_factory):
    from sma_fmu.fmi.packaging.build import build_fmus
    return build_fmus(tmp_path_factory.mktemp("fmi3"), native=True, fmi_version=3)["SmaScenarioSignals"]


def test_native_fmi3_signals_replay_a_restored_state_on_the_saved_grid(fmi3_signals):
    first, second = _two_passes(fmi3_signals)
    assert first == second and first[-1] != first[0]


def test_native_fmi2_signals_replay_a_restored_state_on_the_saved_grid(native_fmus):
    first, second = _two_passes(native_fmus["SmaScenarioSignals"])
    assert first == second and first[-1] != first[0]


def test_pythonfmu_signals_replay_a_restored_state_on_the_saved_grid(fmus):
    first, second = _two_passes(fmus["SmaScenarioSignals"])
    assert first == second and first[-1] != first[0]
