"""A wire with the range its data covered (validity.T_data_min ... stress_data_max): the plant
and the compensator FMUs of both families and both FMI versions log one warning per instance
when a run leaves that range (naming the bound and its value, the same text everywhere), and
run on; a run that stays inside it logs none."""
import re

import pytest

from fmi3_twins import Instance3
from native_twins import Instance
from sma_fmu.files.package_data import default_parameter_file
from sma_fmu.runtime.reachable_band import reachable_band
from sma_fmu.runtime.validity import DATA_RANGE_NOTE
from sma_fmu.wire.parameter_file import load_parameters

pytestmark = pytest.mark.needs("gcc")

RANGE = '''T_data_min = { value = 5.0, unit = "degC", meaning = "lowest data temperature" }
T_data_max = { value = 100.0, unit = "degC", meaning = "highest data temperature" }
stress_data_min = { value = 50.0, unit = "MPa", meaning = "lowest data stress" }
stress_data_max = { value = 200.0, unit = "MPa", meaning = "highest data stress" }
'''
MODELS = ["SmaActuator", "SmaFeedforward"]
KINDS = ("py", "nat", "fmi3")


@pytest.fixture(scope="module")
def range_file(tmp_path_factory):
    text = default_parameter_file().read_text(encoding="utf-8") + RANGE
    path = tmp_path_factory.mktemp("data_range") / "ranged.toml"
    path.write_text(text, encoding="utf-8")
    assert load_parameters(path).data_range
    return path


@pytest.fixture(scope="module")
def families(tmp_path_factory, range_file):
    from sma_fmu.fmi.packaging.build import build_fmus
    from sma_fmu.fmi.packaging.c_family_build import build_native_fmus
    from sma_fmu.fmi.packaging.fmi3_build import build_fmi3_fmus
    root = tmp_path_factory.mktemp("families_range")
    return {"py": build_fmus(root / "py", range_file, names=MODELS),
            "nat": build_native_fmus(root / "nat", range_file, names=MODELS),
            "fmi3": build_fmi3_fmus(root / "fmi3", range_file, names=MODELS)}


def _instance(families, kind, model, name):
    path = families[kind][model]
    return Instance3(path, name) if kind == "fmi3" else Instance(path, name)


def _data_warnings(log):
    """The texts of the data-range warnings in a log, without the FMI function's name."""
    return [re.sub(r"^.*?fmi[23]\w+: ", "", text) for status, text in log
            if DATA_RANGE_NOTE in text and status == 1]


def _heat_and_cool(side, power, steps):
    """Two heating and cooling cycles of ``power`` [W]; every step must pass (warnings too)."""
    time = 0.0
    for cycle in range(2):
        for level in (power, 0.0):
            side.set("P_in", level)
            for _ in range(steps):
                assert side.step(time, 0.01) <= 1, side.log[-2:]
                time += 0.01
    return side.values()["T"]


@pytest.mark.parametrize("power, leaves", [(5.0, True), (0.5, False)])
def test_the_plant_warns_once_per_instance_when_it_leaves_the_data_range(families, range_file,
                                                                         power, leaves):
    params = load_parameters(range_file)
    hottest = params.T_room + params.K_th * power      # the steady state of the held power
    assert (hottest > params.T_data_max) == leaves
    texts = {}
    for kind in KINDS:
        for copy in (1, 2):
            side = _instance(families, kind, "SmaActuator", f"range-plant-{kind}-{power}-{copy}")
            try:
                assert side.start({"load": 0.15}) == 0, side.log[-2:]   # 83 MPa: inside
                assert _data_warnings(side.log) == []
                _heat_and_cool(side, power, 1500)
                texts[kind, copy] = _data_warnings(side.log)
            finally:
                side.close()
    if not leaves:
        assert all(found == [] for found in texts.values()), texts
        return
    first = texts["py", 1]
    assert len(first) == 1 and first[0].startswith("T = 100.") and \
        "is above validity.T_data_max = 100 degC" in first[0], first
    assert all(found == first for found in texts.values()), texts


def test_the_compensator_warns_once_per_instance_about_a_load_outside_the_data(families,
                                                                                range_file):
    params = load_parameters(range_file)
    heavy = 0.5                                          # 277 MPa: above the data, below 300
    assert params.load_data_max < heavy < params.load_max
    band = reachable_band(0.15, params)
    texts = {}
    for kind in KINDS:
        side = _instance(families, kind, "SmaFeedforward", f"range-ff-{kind}")
        try:
            middle = 0.5 * (band.hot + band.cold)
            assert side.start({"R_ref": middle, "load": 0.15}) == 0, side.log[-2:]
            time = 0.0
            for load in (0.15, heavy, 0.15, heavy):
                side.set("load", load)
                for _ in range(50):
                    assert side.step(time, 1e-3) <= 1, side.log[-2:]
                    time += 1e-3
            texts[kind] = _data_warnings(side.log)
        finally:
            side.close()
    first = texts["py"]
    assert len(first) == 1 and first[0].endswith(
        f"load = 0.5 kg is above {params.load_data_max:.4g} kg (validity.stress_data_max = "
        f"200 MPa on a 0.15 mm wire): {DATA_RANGE_NOTE}"), first
    assert texts["nat"] == first and texts["fmi3"] == first
