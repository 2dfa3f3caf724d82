"""Stroke scenarios in the batch engine: two scenarios with the same stroke reference at other
loads map it to other R_ref (no shared reference column), each the library path's."""
import numpy as np

from sma_fmu.cosim.loop import run_library
from sma_fmu.cosim.scenario import load_scenario
from sma_fmu.files.package_data import shipped_file
from sma_fmu.studies.batch import run_batch

SCENARIO = """
[scenario]
model = "{model}"
stop_time_s = 1.0
step_s = 0.005

[reference]
quantity = "stroke"
kind = "cosine"
offset_mm = 8.0
amplitude_mm = 3.0
frequency_hz = 1.0

[load]
times_s = [0.0]
values_kg = [{load}]

[controller]
kind = "pi+ff-adaptive"
"""


def test_same_stroke_other_loads_get_their_own_r_ref(tmp_path):
    scenarios = []
    for load in (0.05, 0.15):
        path = tmp_path / f"stroke-{load}.toml"
        path.write_text(SCENARIO.format(model=shipped_file("models", "reference_wire.toml"),
                                        load=load))
        scenarios.append(load_scenario(path))
    runs = run_batch(scenarios, record="timeseries")
    references = []
    for scenario, run in zip(scenarios, runs):
        library = run_library(scenario).data
        assert np.array_equal(run.data["R_ref"], library["R_ref"])
        assert np.allclose(run.data["R"], library["R"], rtol=0.0, atol=1e-9)
        references.append(library["R_ref"])
    assert not np.allclose(references[0], references[1])
