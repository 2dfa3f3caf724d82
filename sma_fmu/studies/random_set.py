"""Random sets of scenarios for the batch engine's benchmark and equality checks.

Every controller (:data:`SHIPPED_CONTROLLERS`: pi, pi+ff-fixed, pi+ff-adaptive with the
major and with the minor-loop inverse) in both hysteresis modes (in turn), with random PI
gains, phase-lag times, model load, a two-step load profile, start temperature, reference
offset and amplitude, and wire parameters (a_h, R_P, c_p, nu of the plant; a_c of half of
the compensators' models, so model and wire differ; :data:`WIRES` variants, in turn).
Built with ``dataclasses.replace`` from the shipped load-step scenarios, so ten thousand
take about a second.
"""
import dataclasses
import itertools

import numpy as np

from sma_fmu.cosim.scenario import CONTROLLERS, load_scenario
from sma_fmu.files.package_data import shipped_file
from sma_fmu.runtime.checks import HYSTERESIS_MODES
from sma_fmu.runtime.signals import LoadProfile, ReferenceSignal

__all__ = ["WIRES", "SHIPPED_CONTROLLERS", "ALL_CONTROLLERS", "random_scenarios",
           "gain_grid_scenarios"]

WIRES = 64        # distinct random wires (and models) of a set; runs beyond share them
# (kind, inverse): the controllers of the shipped scenarios, and every combination
SHIPPED_CONTROLLERS = (("pi", "major"), ("pi+ff-fixed", "major"), ("pi+ff-adaptive", "major"),
                       ("pi+ff-adaptive", "minor-loop"))
ALL_CONTROLLERS = SHIPPED_CONTROLLERS + (("pi+ff-fixed", "minor-loop"),)


def _wires(params, draws):
    """[(plant, model) parameters] of the wire variants ``draws`` (rows of 6 numbers in [0, 1))."""
    out = []
    for u in draws:
        wire = params.replace(a_h=62.0 + 12.0 * u[0], R_P=31.0 + 4.0 * u[1],
                              c_p=380.0 + 140.0 * u[2], nu=100.0 + 60.0 * u[3])
        out.append((wire, params.replace(a_c=48.0 + 8.0 * u[4]) if u[5] < 0.5 else params))
    return out


def _bases():
    return {kind: load_scenario(shipped_file("scenarios", f"load-step-{kind}.toml"))
            for kind in CONTROLLERS}


def random_scenarios(count, seed=1, stop_time_s=3.0, load_step_s=None, references=None,
                     controllers=SHIPPED_CONTROLLERS):
    """``count`` random scenarios of ``stop_time_s`` [s] (a whole number of 1 ms steps).

    ``controllers``: the (kind, inverse) pairs, taken in turn with each hysteresis mode.

    The load steps at a random time per run, or at ``load_step_s`` [s] in every run (as
    in a sweep of one load profile: the batch then has one load step, not one per run).
    Each run has its own reference, or one of ``references`` random ones (the batch
    evaluates R_ref(t) once per distinct reference, with the scalar code).
    """
    rng = np.random.default_rng(seed)
    bases = _bases()
    combos = itertools.cycle(itertools.product(controllers, HYSTERESIS_MODES))
    variants = rng.random((references or 1, 2))
    draws = rng.random((WIRES, 6))
    wires = {kind: _wires(base.params, draws) for kind, base in bases.items()}
    out = []
    for _ in range(count):
        (kind, inverse), mode = next(combos)
        base = bases[kind]
        u = rng.random(16)
        wire, model = wires[kind][len(out) % WIRES]
        controller = dataclasses.replace(
            base.controller, Kp=2.0 * u[6], Ki=6.0 * u[7], alpha=2.0 * u[8],
            beta=0.05 + 0.95 * u[9], model_load=0.2 * u[10], inverse=inverse)
        switch = round(0.2 + (stop_time_s - 0.2) * u[11], 3) if load_step_s is None \
            else load_step_s
        shape = (u[12], u[13]) if references is None else variants[int(u[12] * references)]
        reference = ReferenceSignal("cosine", {"offset_ohm": 39.0 + 5.0 * shape[0],
                                               "amplitude_ohm": 2.0 + 5.0 * shape[1],
                                               "frequency_hz": 0.5, "phase_deg": 0.0})
        out.append(dataclasses.replace(
            base, stop_time_s=stop_time_s, hysteresis_mode=mode, controller=controller,
            load=LoadProfile([0.0, switch], [0.3 * u[14], 0.3 * u[15]]),
            reference=reference, T_start=5.0 + 35.0 * rng.random(),
            parameter_set=dataclasses.replace(base.parameter_set, params=wire),
            compensator_parameter_set=dataclasses.replace(base.parameter_set, params=model)))
    return out


def gain_grid_scenarios(count, seed=1, stop_time_s=3.0, name="load-step-pi+ff-adaptive"):
    """``count`` copies of a shipped scenario with random Kp in [0.1, 2], Ki in [0.2, 6]."""
    rng = np.random.default_rng(seed)
    base = load_scenario(shipped_file("scenarios", f"{name}.toml"))
    return [dataclasses.replace(base, stop_time_s=stop_time_s, controller=dataclasses.replace(
        base.controller, Kp=float(rng.uniform(0.1, 2.0)), Ki=float(rng.uniform(0.2, 6.0))))
        for _ in range(count)]
