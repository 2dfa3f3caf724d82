"""The masters' stroke table (cosim/stroke_table.c): a stroke reference of every kind mapped
in C gives the Python map's table text, character for character (R_ref at every step, the
branch of the reference's trend, the loads stepping), and the fmpy master's R_ref(t) read
back from it the Python map's value at every step, on the Flexinol fit (thermal expansion:
the two branches give different R_ref) and on the reference wire (closed form)."""
import pytest

from sma_fmu.cosim.scenario import load_scenario
from sma_fmu.files.package_data import shipped_file
from sma_fmu.runtime.scenario_signals import table_text
from sma_fmu.cosim.stroke_table import stroke_reference_at, stroke_table_program, stroke_table_text
from system_needs import needs

pytestmark = needs("gcc")

KINDS = {   # [reference] of each kind [mm], over a 3-s run
    "constant": 'kind = "constant"\nvalue_mm = 15.0',
    "step": 'kind = "step"\ninitial_mm = 10.0\nfinal_mm = 20.0\ntime_s = 1.0',
    "ramp": 'kind = "ramp"\nstart_mm = 20.0\nend_mm = 8.0\nstart_time_s = 0.5\nend_time_s = 2.5',
    "sine": 'kind = "sine"\noffset_mm = 15.0\namplitude_mm = 6.0\nfrequency_hz = 1.0\nphase_deg = 30.0',
    "cosine": 'kind = "cosine"\noffset_mm = 15.0\namplitude_mm = -6.0\nfrequency_hz = 0.7',
    "table": 'kind = "table"\ntimes_s = [0.0, 0.5, 1.0, 2.0]\nvalues_mm = [10.0, 20.0, 20.0, 12.0]'}
WIRES = {"flexinol_fit.toml": ("[0.0, 1.2, 2.2]", "[0.1, 0.2, 0.3]"),
         "reference_wire.toml": ("[0.0, 1.2]", "[0.0032, 0.05]")}


def _scenario(tmp_path, kind, wire):
    times, loads = WIRES[wire]
    path = tmp_path / f"{kind}-{wire.split('.')[0]}.toml"
    path.write_text(f'[scenario]\nmodel = "{shipped_file("models", wire)}"\nstop_time_s = 3.0\n'
                    f'step_s = 0.001\n\n[reference]\nquantity = "stroke"\n{KINDS[kind]}\n\n'
                    f'[load]\ntimes_s = {times}\nvalues_kg = {loads}\n\n'
                    f'[controller]\nkind = "pi+ff-adaptive"\n')
    return load_scenario(path)


@pytest.fixture(scope="module")
def program(tmp_path_factory):
    return stroke_table_program(tmp_path_factory.mktemp("stroke_table"))


@pytest.mark.parametrize("wire", sorted(WIRES))
@pytest.mark.parametrize("kind", sorted(KINDS))
def test_the_c_stroke_table_is_the_python_maps_text(tmp_path, program, kind, wire):
    scenario = _scenario(tmp_path, kind, wire)
    python = scenario.reference.resistance_table(scenario.step_s, scenario.steps)
    assert stroke_table_text(scenario, program) == table_text(python)
    if kind != "constant":   # the reference moved: R_ref did too
        assert len(set(python["values_ohm"])) > 2
    mapped, h = stroke_reference_at(scenario, program), scenario.step_s
    assert [mapped(k * h) for k in range(scenario.steps + 1)] == [
        scenario.reference.value(k * h) for k in range(scenario.steps + 1)]


def test_both_branches_give_their_own_r_ref_on_the_flexinol_fit(tmp_path):
    """The trend chooses the branch: on the Flexinol fit (thermal expansion) the same stroke and
    load map to different R_ref heating and cooling, so a C trend of the wrong sign would show
    in the table above."""
    reference = _scenario(tmp_path, "constant", "flexinol_fit.toml").reference
    heating, cooling = (reference.map.target(15e-3, 0.2, direction).R_ref for direction in (1, -1))
    assert abs(heating - cooling) > 1e-6


def test_a_refused_map_names_the_scenario(tmp_path, program):
    scenario = _scenario(tmp_path, "constant", "flexinol_fit.toml")
    scenario.reference.load.values[-1] = -1.0   # a load the model does not cover
    with pytest.raises(ValueError, match=r"scenario constant-flexinol_fit: the stroke reference's"):
        stroke_table_text(scenario, program)
