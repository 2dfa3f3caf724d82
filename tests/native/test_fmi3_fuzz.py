"""The C family's fuzz cases through the FMI 3.0 front (issue 39: "bad input gets the same
refusals as in FMI 2.0"): the pinned refusals and 400 random calls per model go to each of
the five models as FMI 2.0 and FMI 3.0 (tests/support/fmi3_fuzz_cases.py); every call gets the same
status from both fronts, and every discard or error a logged message naming the same
variables. The same cases run on sanitized binaries in tests/native/test_native_sanitizers.py."""
import pytest

from fmi3_fuzz_cases import MODELS, run_all

pytestmark = pytest.mark.needs("gcc")


def test_fuzz_cases_are_refused_alike_in_both_versions(native_fmus, fmi3_fmus, capsys):
    found = run_all(native_fmus, fmi3_fmus)
    assert sorted(found) == sorted(MODELS)
    for model, (calls, refused, named) in found.items():
        assert calls >= 400 and refused >= 40 and named >= 10, (model, calls, refused, named)
    with capsys.disabled():
        print("\n" + "; ".join(f"{m}: {c} calls, {r} refused alike ({n} naming a variable)"
                               for m, (c, r, n) in found.items()))
