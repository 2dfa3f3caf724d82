"""The optional model terms of issue 36 (runtime/model_terms.py): their defaults reproduce
today's model exactly, the two-stage branch is the weighted sum of two single-stage logistics
(checked against the formula written out here), its inverse returns T, the stress law and the
length equal their formulas, and a parameter file breaking a rule is refused naming the file,
the key and the value."""
import math
import random

import pytest

from sma_fmu.runtime.constant_load import branch_constants, branch_fractions
from sma_fmu.runtime.constants import BOLTZMANN, KELVIN_OFFSET, STANDARD_GRAVITY
from sma_fmu.runtime.feedforward import FeedforwardStepper
from sma_fmu.runtime.model_terms import domain_widths
from sma_fmu.runtime.parameters import ParameterError
from sma_fmu.runtime.plant import PlantStepper
from sma_fmu.runtime.sensing import sense_temperature, temperature_of_fractions
from sma_fmu.files.package_data import default_parameter_file
from sma_fmu.wire.parameter_file import load_parameters

TWO_STAGE = dict(nu_h=150.0, nu_c=105.0, w2=0.13, a2_h=95.0, b2_h=80.0, a2_c=70.0, b2_c=45.0,
                 nu2_h=45.0, nu2_c=35.0)
STRAIN = dict(alpha_P=1.4e-5, alpha_MF=6.6e-6, T_alpha=22.0, span_ratio_0=0.9,
              span_ratio_sat=1.12, span_stress=120.0)
AT_DEFAULT = dict(nu_h=130.0, nu_c=130.0, w2=0.0, a2_h=95.0, a2_c=70.0, b2_h=1.0, b2_c=2.0,
                  nu2_h=3.0, nu2_c=4.0, alpha_P=0.0, alpha_MF=0.0, T_alpha=-40.0,
                  span_ratio_0=1.0, span_ratio_sat=1.0, span_stress=7.0)


def _plant_run(params, mode, seed):
    rng, plant, rows = random.Random(seed), PlantStepper(params, mode=mode), []
    load = 0.0
    for step in range(3000):
        if step % 300 == 0:
            load = rng.choice([0.0, 0.05, 0.15, 0.25])
        rows.append(tuple(plant.step(rng.choice([0.0, 0.3, 1.0, 2.5, 4.0]), load, 0.01)))
    return rows


def _compensator_run(params, inverse, seed):
    rng, stepper, rows = random.Random(seed), FeedforwardStepper(params, inverse=inverse), []
    for step in range(3000):
        rows.append(tuple(stepper.step(41.85 + 6.05 * math.cos(math.pi * step * 1e-3)
                                       + rng.gauss(0.0, 0.5), 0.05 * (step // 1000), 1e-3)))
    return rows


@pytest.mark.parametrize("mode", ["continuous", "switch"])
def test_terms_given_at_their_defaults_change_nothing(params, mode):
    """nu_h = nu_c = nu, w2 = 0 (with stage-2 values that would matter if it were on), no
    expansion, s = 1: plant and compensator outputs equal, bit for bit, those of the file
    without the terms."""
    at_default = params.replace(**AT_DEFAULT)
    assert not at_default.terms.two_stage and not at_default.terms.strain
    assert _plant_run(at_default, mode, 1) == _plant_run(params, mode, 1)
    for inverse in ("major", "minor-loop"):
        assert _compensator_run(at_default, inverse, 2) == _compensator_run(params, inverse, 2)


def _logistic_sum(T, load, heating, p):
    """xi_MF of the two-stage branch from the formula of DESIGN-36.md, written out."""
    drive = p.eps_T - STANDARD_GRAVITY * load * p.x_T / p.N
    M = 1.0 - p.xi_F_inf * (1.0 - math.exp(-load / p.f_F))
    nu1, nu2 = (p.nu_h, p.nu2_h) if heating else (p.nu_c, p.nu2_c)
    tau1 = (p.a_h + p.b_h * load) if heating else (p.a_c + p.b_c * load)
    tau2 = (p.a2_h + p.b2_h * load) if heating else (p.a2_c + p.b2_c * load)
    q = [1.0 / (1.0 + math.exp(nu * drive / BOLTZMANN * (1.0 / (tau + 273.15) - 1.0 / (T + 273.15))))
         for nu, tau in ((nu1, tau1), (nu2, tau2))]
    return M * ((1.0 - p.w2) * q[0] + p.w2 * q[1]), M


@pytest.mark.parametrize("heating", [True, False])
def test_the_two_stage_branch_is_the_weighted_sum_of_two_logistics(params, heating):
    p = params.replace(**TWO_STAGE)
    for load in (0.0, 0.1, 0.25):
        constants = branch_constants(load, 1 if heating else -1, p)
        for T in [10.0 + 2.5 * k for k in range(80)]:
            expected, M = _logistic_sum(T, load, heating, p)
            xi_mf, xi_p = branch_fractions(T, constants)
            assert xi_mf == pytest.approx(expected, rel=1e-12, abs=1e-15)
            assert xi_p == pytest.approx(M - expected, rel=1e-9, abs=1e-15)
    # and it is not the one-stage branch: stage 2 holds 13 % far above the stage-1 centre
    one = branch_constants(0.0, 1, params.replace(nu_h=150.0))
    two = branch_constants(0.0, 1, p)
    assert branch_fractions(85.0, two)[0] - branch_fractions(85.0, one)[0] > 0.05


@pytest.mark.parametrize("direction", [1, -1])
def test_the_inverse_returns_the_temperature_on_a_two_stage_branch(params, direction):
    p = params.replace(**TWO_STAGE)
    worst, inside = 0.0, 0
    for load in (0.0, 0.05, 0.2, 0.4):
        constants = branch_constants(load, direction, p)
        for T in [0.0 + 0.7 * k for k in range(300)]:
            xi_mf, xi_p = branch_fractions(T, constants)
            sensed = temperature_of_fractions(xi_mf, xi_p, constants, p.saturation_margin)
            if sensed.saturated:
                continue
            inside += 1
            worst = max(worst, abs(sensed.temperature - T))
    assert inside > 600 and worst < 1e-9, (inside, worst)


def test_the_inverse_finds_what_a_finer_search_finds(params):
    """An independent root: scan T in 1 mK steps for the sign change of L(T) - target."""
    p = params.replace(**TWO_STAGE)
    constants = branch_constants(0.1, 1, p)
    for target in (0.05, 0.1, 0.3, 0.6, 0.75):
        sensed = temperature_of_fractions(target, constants.M - target, constants, 1e-6)
        T = 0.0
        while _logistic_sum(T, 0.1, True, p)[0] > target:
            T += 1e-3
        assert abs(sensed.temperature - T) < 2e-3


def test_nu_h_and_nu_c_set_the_widths_of_their_own_branch(params):
    p = params.replace(nu_h=200.0, nu_c=80.0)
    drive = p.eps_T - STANDARD_GRAVITY * 0.1 * p.x_T / p.N
    assert branch_constants(0.1, 1, p).energy_over_kB == pytest.approx(200.0 * drive / BOLTZMANN)
    assert branch_constants(0.1, -1, p).energy_over_kB == pytest.approx(80.0 * drive / BOLTZMANN)


def test_the_stress_law_and_the_length_follow_their_formulas(params):
    p = params.replace(**STRAIN)
    area = math.pi * p.diameter ** 2 / 4.0
    for load in (0.0, 0.05, 0.2, 0.5):
        sigma = STANDARD_GRAVITY * load / area / 1e6
        s = 1.12 + (0.9 - 1.12) * math.exp(-sigma / 120.0)
        plant = PlantStepper(p, T_start=40.0, mode="switch", load=load)
        out = plant.outputs
        offset = 40.0 - 22.0
        expected = (p.l_P * (1 + 1.4e-5 * offset) * out.xi_P
                    + (p.l_P + s * (p.l_M - p.l_P)) * (1 + 6.6e-6 * offset) * out.xi_M
                    + (p.l_P + s * (p.l_F - p.l_P)) * (1 + 6.6e-6 * offset) * out.xi_F)
        assert out.x == pytest.approx(expected, rel=1e-14)
    # far above A_f the wire is all P (and residual F): it grows by alpha_P per kelvin there
    hot = [PlantStepper(p, T_start=T, mode="switch").outputs.x for T in (250.0, 251.0)]
    assert (hot[1] - hot[0]) / p.l_P == pytest.approx(1.4e-5, rel=1e-6)   # dl_P/dT = alpha_P l_P
    # s(0) = span_ratio_0: the no-load actuation stroke is 0.9 of the paper's
    cold = PlantStepper(p, T_start=22.0, mode="switch").outputs.x
    old_cold = PlantStepper(params, T_start=22.0, mode="switch").outputs.x
    assert cold - p.l_P == pytest.approx(0.9 * (old_cold - p.l_P), rel=1e-9)


def _write(tmp_path, extra):
    path = tmp_path / "terms.toml"
    path.write_text(default_parameter_file().read_text(encoding="utf-8") + extra, encoding="utf-8")
    return path


GOOD = """
[second_stage]
w2   = { value = 0.13, unit = "1", meaning = "share of M in stage 2" }
a2_h = { value = 95.0, unit = "degC", meaning = "stage-2 heating centre" }
a2_c = { value = 70.0, unit = "degC", meaning = "stage-2 cooling centre" }

[strain]
alpha_P = { value = 1.4e-5, unit = "1/K", meaning = "expansion of P" }
"""


def test_a_file_with_the_terms_loads_and_round_trips(tmp_path):
    from sma_fmu.wire.parameter_file import load_parameter_set, write_parameter_file
    loaded = load_parameter_set(_write(tmp_path, GOOD))
    assert loaded.params.w2 == 0.13 and loaded.params.terms.two_stage
    assert loaded.params.terms.b2_h == loaded.params.b_h and loaded.params.nu_h is None
    again = load_parameter_set(write_parameter_file(tmp_path / "again.toml", loaded.params, "x"))
    assert again.params == loaded.params


@pytest.mark.parametrize("old, new, match", [
    ("0.13", "1.0", r"second_stage\.w2 = 1\.0 must be in \[0, 1\)"),
    ("95.0", "60.0", r"second_stage\.a2_h = 60\.0 degC must be >= second_stage\.a2_c = 70\.0"),
    ('a2_c = { value = 70.0, unit = "degC", meaning = "stage-2 cooling centre" }', "",
     r"second_stage\.a2_c is required when second_stage\.w2 = 0\.13"),
    ("1.4e-5, unit = \"1/K\"", "1.4e-5, unit = \"1/degC\"", r"strain\.alpha_P has unit '1/degC'"),
])
def test_a_bad_term_is_refused_naming_file_key_and_value(tmp_path, old, new, match):
    assert old in GOOD
    path = _write(tmp_path, GOOD.replace(old, new, 1))
    with pytest.raises(ParameterError, match=match) as caught:
        load_parameters(path)
    assert str(path) in str(caught.value)


def test_sensing_with_a_two_stage_branch_inverts_the_plant(params):
    """The plant's resistance on the major branch, sensed back: its temperature (1e-9 K)."""
    p = params.replace(**TWO_STAGE, **STRAIN)
    for direction, T_start, power in ((1, 20.0, 3.0), (-1, 220.0, 0.0)):
        plant = PlantStepper(p, T_start=T_start, mode="switch", load=0.1)
        for _ in range(2000):
            out = plant.step(power, 0.1, 0.01)
            if out.heating != (direction == 1):
                continue
            sensed = sense_temperature(out.R, 0.1, direction, p)
            if not sensed.saturated:
                assert abs(sensed.temperature - out.T) < 1e-9 * max(1.0, abs(out.T)) * 10



def test_a_second_stage_out_of_range_is_named_when_the_file_is_read(tmp_path):
    """Each value passes its rule, but the stage-2 heating centre falls below 0 K at the
    validity limit's load: the file is refused, naming the second stage."""
    text = GOOD.replace('a2_h = { value = 95.0', 'b2_h = { value = -1000.0, unit = "degC/kg", '
                        'meaning = "x" }\na2_h = { value = 95.0')
    with pytest.raises(ParameterError, match="second-stage centre.*second_stage.a2_h") as caught:
        load_parameters(_write(tmp_path, text))
    assert "terms.toml" in str(caught.value)


def test_a_broad_second_stage_inverts_where_its_own_closed_form_diverges(params):
    """nu2 = 8, w2 = 0.02: stage 2 alone never falls below 0.2 % of M, so its closed form has
    no temperature for a smaller target; the two-stage branch (2 % of M in stage 2) still
    reaches it, hot, and the inverse finds that temperature. Below what the branch reaches
    even infinitely hot, the inverse diverges and says so."""
    p = params.replace(**{**TWO_STAGE, "nu2_h": 8.0, "nu2_c": 8.0, "w2": 0.02})
    constants = branch_constants(0.05, 1, p)
    floor = constants.M * p.w2 / (1.0 + math.exp(constants.energy2_over_kB * constants.inv_centre2_K))
    checked = 0
    for T in (350.0, 450.0, 700.0, 1000.0):
        xi_mf, xi_p = branch_fractions(T, constants)
        stage2_alone = constants.inv_centre2_K - math.log(xi_p / xi_mf) / constants.energy2_over_kB
        assert stage2_alone <= 0.0 and xi_mf > floor        # the case meant
        sensed = temperature_of_fractions(xi_mf, xi_p, constants, p.saturation_margin)
        assert not sensed.saturated and abs(sensed.temperature - T) < 1e-9 * T
        checked += 1
    assert checked == 4
    with pytest.raises(ValueError, match="does not reach the target at any temperature"):
        temperature_of_fractions(0.5 * floor, constants.M - 0.5 * floor, constants, 1e-9)


def test_one_width_is_both_and_two_widths_give_their_geometric_mean(params):
    """domain_widths: a file's one nu is both widths, as the runtime's terms read it; two
    widths give nu = sqrt(nu_h nu_c) (written out here), and one nu gives itself back."""
    assert domain_widths({"nu": params.nu}) == {"nu_h": params.terms.nu_h,
                                                "nu_c": params.terms.nu_c, "nu": params.nu}
    two = domain_widths({"nu_h": 150.0, "nu_c": 96.0, "other": 1.0})
    assert two == {"nu_h": 150.0, "nu_c": 96.0, "nu": 120.0}
    assert domain_widths(domain_widths({"nu": 130.0}))["nu"] == 130.0
    assert domain_widths({"nu_h": -1.0, "nu_c": 4.0})["nu"] == -1.0   # no mean of a negative
