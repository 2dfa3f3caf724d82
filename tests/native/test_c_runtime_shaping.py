"""The C compensator with shaping "reachable" (c_family/runtime: shaping, feedforward, plant)
equals the Python runtime's, step by step and bit for bit.

Long random R_ref/load walks (nested reversals, holds, saturation at both ends, load changes
also far above the validity limit, an unconnected start, varied steps, a full minor-loop
memory) through both inverses, without and with a power cap, without and with the
anticipation of the lower turn (the walk's holds are steps it must not take for turns); mid-walk the saved state (the
compensator's and its model wire's) goes through C and through Python's state() into C.
Bad arguments and bad states are refused by both with the same message and change nothing.
"""
import math
import random

import pytest

from sma_fmu.runtime.feedforward import FeedforwardStepper

from c_feedforward import (CParameters, CStepper, doubles_of, load_library, normalized,
                           reference_walk, same_doubles)


@pytest.fixture(scope="module")
def lib(tmp_path_factory):
    return load_library(tmp_path_factory.mktemp("c_shaping"))


CASES = [  # (seed, inverse, adapt_to_load, power cap [W] or None, memory depth, anticipation [s])
    (21, "major", True, None, 64, 0.0),
    (22, "minor-loop", True, None, 64, 0.15),
    (23, "minor-loop", True, 10.0, 6, 0.0),
    (24, "major", False, 3.0, 64, 0.3),
    (25, "minor-loop", False, None, 4, 0.0),
    (26, "major", True, 0.5, 8, 0.0),
]
STEPS = 6000


def pair(lib, params, inverse, adapt, cap, lead=0.0):
    keywords = {"adapt_to_load": adapt, "inverse": inverse, "shaping": "reachable",
                "power_cap": cap, "anticipation": lead}
    cparams = CParameters(lib, params)
    return (FeedforwardStepper(params, **keywords), CStepper(lib, cparams, params, **keywords),
            cparams, keywords)


def compare(python, c, sample):
    expected = tuple(python.step(*sample))
    assert c.step(*sample) == expected, sample
    warnings = [w if w is None else normalized(w) for w in (c.warning, python.warning)]
    assert warnings[0] == warnings[1], sample
    return expected


@pytest.mark.parametrize("seed, inverse, adapt, cap, depth, lead", CASES)
def test_the_shaped_c_compensator_equals_the_python_one(lib, params, seed, inverse, adapt, cap,
                                                        depth, lead):
    params = params.replace(memory_depth=depth)
    rng = random.Random(seed)
    python, c, cparams, keywords = pair(lib, params, inverse, adapt, cap, lead)
    walk = reference_walk(rng, params, STEPS)
    assert c.initial_outputs(*walk[0][:2]) == tuple(python.initial_outputs(*walk[0][:2]))
    seen = {"moved": 0, "capped": 0, "passive": 0, "deepest": 0, "load warnings": 0,
            "anticipated": 0}
    restart = rng.randrange(STEPS // 3, 2 * STEPS // 3)
    others = []
    for index, sample in enumerate(walk):
        outputs = compare(python, c, sample)
        for other in others:
            assert other.step(*sample) == outputs
        seen["moved"] += outputs[2]
        seen["capped"] += cap is not None and outputs[0] == cap
        seen["passive"] += outputs[0] == 0.0 and sample[0] > 0.0
        seen["deepest"] = max(seen["deepest"], len(python._shaper.model.reversals))
        seen["load warnings"] += bool(python.warning and "load" in python.warning)
        seen["anticipated"] += bool(lead) and python._anticipation.held is not None
        if index % 97 == 0:
            assert same_doubles(c.state(), doubles_of(python.state())), index
        if index == restart:
            state, saved = python.state(), c.state()
            python = FeedforwardStepper(params, **keywords)
            python.restore(state)
            c = CStepper(lib, cparams, params, **keywords)
            c.restore(saved)
            from_python = CStepper(lib, cparams, params, **keywords)
            from_python.restore(doubles_of(state))
            assert same_doubles(from_python.state(), saved)
            others.append(from_python)
    print(f"seed {seed} {inverse} cap {cap}: {seen}")
    assert seen["moved"] > 0 and seen["passive"] > 0 and seen["load warnings"] > 0
    assert cap is None or seen["capped"] > 0
    assert (seen["anticipated"] > 0) == (lead > 0)
    if inverse == "minor-loop":   # a small memory fills; the model's stack is shallower
        assert seen["deepest"] == depth if depth <= 6 else seen["deepest"] > 2


def refusal(call):
    with pytest.raises(ValueError) as caught:
        call()
    return str(caught.value)


def test_bad_shaping_arguments_are_refused_alike(lib, params):
    cparams = CParameters(lib, params)
    for keywords in ({"shaping": "Reachable"}, {"shaping": "50%s%n"}, {"shaping": None},
                     {"shaping": "reachable", "power_cap": 0.0},
                     {"shaping": "reachable", "power_cap": -1.0},
                     {"shaping": "reachable", "power_cap": math.inf},
                     {"shaping": "none", "power_cap": 10.0}):
        message = refusal(lambda: FeedforwardStepper(params, **keywords))
        got = refusal(lambda: CStepper(lib, cparams, params, **keywords))
        assert normalized(got) == normalized(message), keywords


def bad_model_states(state):
    """(Python state with a broken model wire, the name its message gives)."""
    def with_model(**entries):
        return {**state, "model": {**state["model"], **entries}}
    return [(with_model(temperature=1e9), "temperature"),
            (with_model(direction=0), "direction"),
            (with_model(xi_MF=2.0), "xi_MF"),
            (with_model(load=-1.0), "load"),
            (with_model(reversals=[[40.0, 7.0]]), "reversals[0]")]


@pytest.mark.parametrize("inverse", ["major", "minor-loop"])
def test_bad_model_states_are_refused_alike_and_change_nothing(lib, params, inverse):
    python, c, _, _ = pair(lib, params, inverse, True, None)
    walk = reference_walk(random.Random(7), params, 600)
    for sample in walk[:300]:
        compare(python, c, sample)
    before, before_python = c.state(), python.state()
    for state, name in bad_model_states(python.state()):
        message = refusal(lambda: python.restore(state))
        got = refusal(lambda: c.restore(doubles_of(state)))
        assert message.startswith("state entry model: ") and name in message
        assert normalized(got) == normalized(message), name
        assert same_doubles(c.state(), before) and python.state() == before_python
    missing = {key: value for key, value in before_python.items() if key != "model"}
    assert "lacks entry model" in refusal(lambda: python.restore(missing))
    for sample in walk[300:]:
        compare(python, c, sample)
