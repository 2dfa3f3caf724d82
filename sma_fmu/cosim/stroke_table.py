"""A stroke reference's R_ref at every step, mapped in C (``stroke_table.c``), for the masters.

The FMUs hold no stroke map: a master gives the signals FMU the R_ref the stroke maps to at
every step, as a table (:meth:`~sma_fmu.runtime.stroke.StrokeReference.resistance_table`).
In Python that mapping costs some 90 us a step on the Flexinol fit (a secant search per new
stroke): about 2.7 s over a 30-s run of the 0.5 Hz profile, more than the C master's whole
loop. :func:`stroke_table_text` maps the steps in C with the C family's runtime (its signals
and stroke map equal Python's to the double) and writes the table as Python does
(:func:`~sma_fmu.runtime.stroke.step_table`, ``table_text``): the same text, character for
character; the C master gives it to the signals FMU. The fmpy master samples the same table
in its loop (:func:`stroke_reference_at`). The program is compiled once per source and
compiler (:func:`~sma_fmu.fmi.packaging.runtime_program.runtime_program`); where no C
compiler is (a wheel's prebuilt binaries only), :func:`available_program` is None and both
masters map the stroke in Python, the same values.
"""
import array
import os
import subprocess
from pathlib import Path

from sma_fmu.fmi.hosts import CHostError
from sma_fmu.fmi.packaging.runtime_program import runtime_program, wire_numbers
from sma_fmu.runtime.scenario_signals import table_text
from sma_fmu.runtime.signals import REFERENCE_KINDS, reference_from_table, unit_key
from sma_fmu.runtime.stroke import step_table

__all__ = ["SOURCE", "stroke_table_program", "available_program", "stroke_table_input",
           "stroke_values", "stroke_table_text", "stroke_reference_at"]

SOURCE = Path(__file__).parent / "stroke_table.c"


_PROGRAMS = {}   # the program's executable, by cache folder and compiler settings


def stroke_table_program(cache=None):
    """The compiled ``stroke_table.c`` (``cache``: its build folder, default the temporary
    folder), looked up once per process (finding it hashes the sources)."""
    key = (str(cache), os.environ.get("CC"), os.environ.get("PATH"))
    program = _PROGRAMS.get(key)
    if program is None or not program.is_file():
        program = _PROGRAMS[key] = runtime_program(SOURCE, cache)
    return program


def available_program(cache=None):
    """:func:`stroke_table_program`'s, or None when it cannot be built (no C compiler: the
    stroke is then mapped in Python)."""
    try:
        return stroke_table_program(cache)
    except CHostError:
        return None


def _array(values):
    return [len(values), *values]


def stroke_table_input(scenario):
    """The numbers ``stroke_table.c`` reads for ``scenario`` (a stroke reference), as text."""
    reference = scenario.reference
    params, signal, load = reference.map.params, reference.signal, reference.load
    numbers = wire_numbers(params) + [reference.map.start_length, list(REFERENCE_KINDS).index(signal.kind)]
    required, optional = REFERENCE_KINDS[signal.kind]   # stroke_table.c reads them in this order

    def setting(key):   # the kinds' own keys (..._ohm) in the signal's unit (..._mm)
        return signal.settings.get(unit_key(key, signal.unit), optional.get(key))

    if signal.kind == "table":
        numbers += _array(setting("times_s")) + _array(setting("values_ohm"))
    else:
        numbers += [setting(key) for key in required + tuple(optional)]
    numbers += _array(load.times) + _array(load.values) + [scenario.step_s, scenario.steps]
    return " ".join(map(repr, map(float, numbers)))


def stroke_values(scenario, program=None):
    """R_ref [ohm] at t_k = k h, k = 0 ... steps, of ``scenario`` (a stroke reference),
    computed in C: ``scenario.reference.value(k h)`` to the double. ``program``:
    :func:`stroke_table_program`'s (None: that of the temporary folder). Raises
    :class:`~sma_fmu.fmi.hosts.CHostError` when it cannot be built and ``ValueError`` with
    the map's message when it refuses."""
    program = stroke_table_program() if program is None else program
    result = subprocess.run([str(program)], input=stroke_table_input(scenario).encode("ascii"),
                            capture_output=True)
    if result.returncode != 0:
        raise ValueError(f"scenario {scenario.name}: the stroke reference's R_ref table: "
                         f"{result.stderr.decode('utf-8', 'replace').strip()}")
    values = array.array("d", result.stdout)
    if len(values) != scenario.steps + 1:
        raise ValueError(f"scenario {scenario.name}: the stroke reference's R_ref table: "
                         f"{len(values)} values for {scenario.steps + 1} steps")
    return values.tolist()


def stroke_table_text(scenario, program=None):
    """The signals FMU's ``reference`` text of ``scenario`` (a stroke reference): the JSON
    text :func:`~sma_fmu.runtime.scenario_signals.table_text` writes of
    ``scenario.reference.resistance_table(scenario.step_s, scenario.steps)``, computed in C
    (:func:`stroke_values`)."""
    return table_text(step_table(scenario.step_s, stroke_values(scenario, program)))


def stroke_reference_at(scenario, program):
    """R_ref(t) [ohm] of ``scenario`` (a stroke reference) for a loop that samples it at
    t_k = k h: the table :func:`stroke_table_text` writes, read back (it gives its knots, and
    the held values between them, exactly at those times: the Python map's values), or the
    Python map itself when ``program`` is None (no C compiler)."""
    if program is None:
        return scenario.reference.value
    return reference_from_table(step_table(scenario.step_s, stroke_values(scenario, program))).value
