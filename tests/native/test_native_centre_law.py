"""Both FMU families built from a parameter file with the Clausius-Clapeyron centres on
(hysteresis.cc_share_h, cc_share_c beside the stress law): the shares are FMU parameters of
both families, and the plant and the compensator of the two families agree bit for bit and
equal the library steppers of that file, also with a share set by the host."""
import pytest

from native_twins import Instance, compensator_walk, plant_walk
from sma_fmu.files.package_data import default_parameter_file
from sma_fmu.runtime.feedforward import FeedforwardStepper
from sma_fmu.runtime.plant import PlantStepper
from sma_fmu.runtime.reachable_band import reachable_band
from sma_fmu.wire.parameter_file import load_parameters

pytestmark = pytest.mark.needs("gcc")

SHARES = '''[hysteresis]
cc_share_h = { value = 1.0, unit = "1", meaning = "heating slope follows s(sigma)" }
cc_share_c = { value = 0.6, unit = "1", meaning = "cooling slope follows s(sigma)" }
'''
LAW = '''[strain]
span_ratio_0 = { value = 0.2,   unit = "1",   meaning = "s at no stress" }
span_stress  = { value = 150.0, unit = "MPa", meaning = "stress scale" }

[constant_temperature]'''
MODELS = ("SmaActuator", "SmaFeedforward")


@pytest.fixture(scope="module")
def law_file(tmp_path_factory):
    text = default_parameter_file().read_text(encoding="utf-8")
    assert "[hysteresis]\n" in text and "[constant_temperature]" in text
    text = text.replace("[hysteresis]\n", SHARES, 1).replace("[constant_temperature]", LAW, 1)
    path = tmp_path_factory.mktemp("law") / "law.toml"
    path.write_text(text, encoding="utf-8")
    params = load_parameters(path)
    assert params.terms.cc_share_h == 1.0 and params.terms.span_ratio_0 == 0.2
    return path


@pytest.fixture(scope="module")
def families(tmp_path_factory, law_file):
    from sma_fmu.fmi.packaging.build import build_fmus
    from sma_fmu.fmi.packaging.c_family_build import build_native_fmus
    root = tmp_path_factory.mktemp("families_law")
    return {"py": build_fmus(root / "py", law_file, names=list(MODELS)),
            "nat": build_native_fmus(root / "nat", law_file, names=list(MODELS))}


def _pair(families, model, tag, start):
    sides = [Instance(families[family][model], f"{tag}-{family}") for family in ("py", "nat")]
    for side in sides:
        assert side.start(start) == 0, side.log[-2:]
    return sides


def test_the_shares_are_parameters_of_both_families(families):
    for family in ("py", "nat"):
        for model in MODELS:
            side = Instance(families[family][model], f"law-vars-{family}-{model}")
            try:
                for name, start in (("cc_share_h", 1.0), ("cc_share_c", 0.6)):
                    variable = side.variables[name]
                    assert variable.causality == "parameter" and float(variable.start) == start
            finally:
                side.close()


@pytest.mark.parametrize("share_c", [None, 0.2])
def test_the_plants_agree_bit_for_bit_and_equal_the_library(families, law_file, share_c):
    params = load_parameters(law_file).replace(memory_depth=3)
    start = {"hysteresis_mode": 1, "memory_depth": 3, "load": 0.2}
    if share_c is not None:
        params = params.replace(cc_share_c=share_c)
        start["cc_share_c"] = share_c
    library = PlantStepper(params, mode="continuous", load=0.2)
    py, nat = _pair(families, "SmaActuator", f"law-plant{share_c}", start)
    try:
        plant_walk((py, nat), library, 7, 5000, 0.2, load_rate=0.004)
    finally:
        py.close()
        nat.close()


def test_the_compensators_agree_bit_for_bit_and_equal_the_library(families, law_file):
    params = load_parameters(law_file)
    band = reachable_band(0.15, params)
    library = FeedforwardStepper(params.replace(memory_depth=3), inverse="minor-loop")
    library.initial_outputs(band.cold, 0.15)
    py, nat = _pair(families, "SmaFeedforward", "law-ff",
                    {"inverse": 2, "memory_depth": 3, "R_ref": band.cold, "load": 0.15})
    try:
        assert compensator_walk((py, nat), library, 3, 4000, band, 0.15) > 2000
    finally:
        py.close()
        nat.close()
