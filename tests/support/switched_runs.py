"""One SmaActuator script run twice, with a switch of the C front on and off, for the tests
that prove a front shortcut (the fast path, the direct step) answers exactly as the slow
route does: :func:`run_switched` runs it, :func:`same` compares what the runs returned."""
import math

from sma_fmu.fmi.driving.instance import FmuInstance


def run_switched(fmus, monkeypatch, switch, enabled, script, warm=None, cleared=()):
    """``script(fmu)``'s result on a SmaActuator instance of ``fmus`` with the environment
    switch ``switch`` (e.g. SMA_FMU_NO_FAST_PATH, read when an instance is created) cleared
    (``enabled``) or set; the switches in ``cleared`` are cleared either way; ``warm(fmu)``
    runs first. The script ends with fmi2Terminate; the instance is freed here."""
    if enabled:
        monkeypatch.delenv(switch, raising=False)
    else:
        monkeypatch.setenv(switch, "1")
    for name in cleared:
        monkeypatch.delenv(name, raising=False)
    with FmuInstance(fmus["SmaActuator"], "plant", {"load": 0.05}) as fmu:
        if warm is not None:
            warm(fmu)
        results = script(fmu)
        fmu._alive = False  # terminated by the script
        fmu._fmu.freeInstance()
    return results


def same(a, b):
    """Equal, NaN equal to NaN, through lists, tuples and dicts."""
    if isinstance(a, float) and isinstance(b, float) and math.isnan(a) and math.isnan(b):
        return True
    if isinstance(a, (list, tuple)) and isinstance(b, (list, tuple)):
        return len(a) == len(b) and all(same(x, y) for x, y in zip(a, b))
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(same(a[k], b[k]) for k in a)
    return a == b
