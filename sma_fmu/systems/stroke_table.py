"""A stroke reference's R_ref table for the signals FMU, mapped in C (``stroke_table.c``).

The FMUs hold no stroke map: a master gives the signals FMU the R_ref the stroke maps to at
every step, as a table (:meth:`~sma_fmu.runtime.stroke.StrokeReference.resistance_table`).
In Python that mapping costs some 90 us a step on the Flexinol fit (a secant search per new
stroke): about 2.7 s before a 30-s run of the 0.5 Hz profile, more than the C master's whole
loop. :func:`stroke_table_text` maps the steps in C with the C family's runtime (its signals
and stroke map equal Python's to the double) and writes the table as Python does
(:func:`~sma_fmu.runtime.stroke.step_table`, ``table_text``): the same text, character for
character; the C master uses it. The program is compiled once per source and compiler
(:func:`~sma_fmu.fmi.packaging.runtime_program.runtime_program`).
"""
import array
import os
import subprocess
from pathlib import Path

from sma_fmu.fmi.packaging.runtime_program import runtime_program, wire_numbers
from sma_fmu.runtime.scenario_signals import table_text
from sma_fmu.runtime.signals import REFERENCE_KINDS, unit_key
from sma_fmu.runtime.stroke import step_table

__all__ = ["SOURCE", "is_stroke", "stroke_table_program", "stroke_table_input", "stroke_table_text"]

SOURCE = Path(__file__).parent / "stroke_table.c"


_PROGRAMS = {}   # the program's executable, by cache folder and compiler settings


def is_stroke(scenario):
    """Whether ``scenario``'s reference is a stroke."""
    return getattr(scenario.reference, "quantity", None) == "stroke"


def stroke_table_program(cache=None):
    """The compiled ``stroke_table.c`` (``cache``: its build folder, default the temporary
    folder), looked up once per process (finding it hashes the sources)."""
    key = (str(cache), os.environ.get("CC"), os.environ.get("PATH"))
    program = _PROGRAMS.get(key)
    if program is None or not program.is_file():
        program = _PROGRAMS[key] = runtime_program(SOURCE, cache)
    return program


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


def stroke_table_text(scenario, program=None):
    """The signals FMU's ``reference`` text of ``scenario`` (a stroke reference): the JSON
    text :func:`~sma_fmu.runtime.scenario_signals.table_text` writes of
    ``scenario.reference.resistance_table(scenario.step_s, scenario.steps)``, computed in C.
    ``program``: :func:`stroke_table_program`'s (None: that of the temporary folder). Raises
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
    return table_text(step_table(scenario.step_s, values.tolist()))
