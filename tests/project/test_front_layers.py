"""The C files of both families and of the hosts call each other down one way only (issues 30,
37: no circle).

fmi2_exports.c (the 34 FMI functions) is the top: nothing calls back up into it, but for
combined_step.c above it (sma_fmu_step: nothing but FMI calls, in one call for the fmpy
master), which nothing calls. The
saved states (fmi2_states.c), the instance bookkeeping (instances.c) and the fast path call
down into call_status.c (refuse, finish), which calls only the host logger. The test builds
the graph "file A calls a function file B defines" from the sources and asserts it has no
cycle, and that fmi2_exports.c defines nothing another file calls but its FMI exports. The
same check runs over the C family (its runtime, FMI layer and model adapters, compiled together
into one binary). The C hosts are separate programs (each its own main), not one graph.
"""
import re
from pathlib import Path

import sma_fmu.fmi as fmi
from graph_cycles import find_cycle
from sma_fmu.fmi.packaging.c_family_build import c_source_folders

FMI = Path(fmi.__file__).parent
FRONT = FMI / "python_family" / "front"
C_FAMILY = c_source_folders()   # runtime, core, both fronts, adapters (models/<Model>/), c_common
_DEFINITION = re.compile(r"^(?!static\b)[A-Za-z_][^\n;(=]*?\b([A-Za-z_]\w*)\s*\([^;{]*\)\s*\{", re.M)


def _defined(text):
    """Names of the non-static functions a C file defines (a head, then its body's brace)."""
    return {match.group(1) for match in _DEFINITION.finditer(text)} - {
        "if", "for", "while", "switch", "return", "sizeof"}


def _unit(name):
    """A file, or the pair of one platform's alternatives (platform_posix.c and
    platform_windows.c define the same functions; one of them is compiled)."""
    return re.sub(r"_(posix|windows)\.c$", "_*.c", name)


def _graph(folders=(FRONT, FMI / "c_common")):
    texts = {}
    for path in sorted(path for folder in folders for path in folder.glob("*.c")):
        text = re.sub(r"/\*.*?\*/|//[^\n]*", "", path.read_text(encoding="utf-8"), flags=re.S)
        texts[_unit(path.name)] = texts.get(_unit(path.name), "") + text
    defined = {name: _defined(text) for name, text in texts.items()}
    calls = {}
    for caller, text in texts.items():
        calls[caller] = {owner for owner, names in defined.items() if owner != caller and any(
            re.search(rf"\b{re.escape(n)}\s*\(", text) for n in names)}
    return defined, calls


def test_the_front_calls_down_only():
    defined, calls = _graph()
    assert "refuse" in defined["call_status.c"] and "free_instance_memory" in defined["instances.c"]
    assert find_cycle(calls) is None, f"C files call each other in a circle: {' -> '.join(find_cycle(calls))}"
    callers_of_exports = [name for name, targets in calls.items() if "fmi2_exports.c" in targets]
    assert callers_of_exports == ["combined_step.c"], f"{callers_of_exports} call up into fmi2_exports.c"
    assert not [name for name, targets in calls.items() if "combined_step.c" in targets]
    assert defined["combined_step.c"] == {"sma_fmu_step"}


def test_the_check_finds_a_circle():
    assert find_cycle({"a.c": {"b.c"}, "b.c": {"c.c"}, "c.c": {"a.c"}}) == ["a.c", "b.c", "c.c", "a.c"]
    assert find_cycle({"a.c": {"b.c"}, "b.c": set()}) is None


def test_the_c_family_calls_down_only():
    defined, calls = _graph(C_FAMILY)
    assert len(defined) >= 3 and any(calls.values())   # the walk sees real files and calls
    assert find_cycle(calls) is None, f"C files call each other in a circle: {' -> '.join(find_cycle(calls))}"
