"""The C family's wire parameter table, generated from the Python schema at build time.

``sma_parameters_table.h`` (:func:`parameter_table_header`) is written from
:data:`~sma_fmu.runtime.parameters.PARAMETER_SPECS`, the fields of
:class:`~sma_fmu.runtime.parameters.WireParameters` and
:data:`~sma_fmu.runtime.model_terms.TERM_DEFAULTS`, so the C family never holds a second copy
of the schema: c_family/runtime/parameters.h and .c expand its X-macro lists (the enum
ParameterIndex, the spec rows, the fields of WireParameters and ModelTerms, the copies, the
defaults). Its order is PARAMETER_SPECS': the layout of ``values[]`` and of
``resources/model_starts.json``'s ``wire_defaults``. A new optional parameter is a row of
PARAMETER_SPECS (and of TERM_DEFAULTS when it is a model term), never a C edit.

Every build of the C family gets it: ``c_family_build.c_source_folders`` lists it beside the shipped
C files (so it lands in every FMU's ``sources/``, where tools and ``buildDescription.xml``
compile it), from :func:`generated_folder`, which C test programs pass as an include folder.
"""
import dataclasses
import hashlib
import math
import os
import tempfile
from pathlib import Path

from sma_fmu.runtime.minor_loops import DEFAULT_DEPTH
from sma_fmu.runtime.model_terms import TERM_DEFAULTS
from sma_fmu.runtime.parameters import (DEFAULT_STRESS_MAX, MAX_MEMORY_DEPTH, PARAMETER_SPECS,
                                        RULES, WireParameters, range_text)

__all__ = ["TABLE_HEADER", "parameter_table_header", "generated_files", "generated_folder"]

TABLE_HEADER = "sma_parameters_table.h"
_C_TYPES = {float: "double", int: "int"}


def _number(value):
    """A C literal of ``value`` (exact: repr round-trips), NAN for None."""
    if value is None:
        return "NAN"
    if isinstance(value, int):
        return str(value)
    if not math.isfinite(value):
        raise ValueError(f"parameter default {value!r} is not finite")
    return repr(float(value))


def _wire_fields():
    """[(C type, name)] of the parameters WireParameters holds as its own fields, in its
    field order (the model terms are held by ModelTerms)."""
    terms = {name for name, _ in TERM_DEFAULTS}
    specs = {spec.name for spec in PARAMETER_SPECS}
    return [(_C_TYPES[f.type], f.name)
            for f in dataclasses.fields(WireParameters)
            if f.init and f.name in specs and f.name not in terms]


def _fallback(default, earlier):
    """The C expression of a TERM_DEFAULTS default: a term above (t->), a parameter (p->),
    a number, or NAN for None."""
    if isinstance(default, str):
        return f"t->{default}" if default in earlier else f"p->{default}"
    return _number(default)


def _list(name, what, rows):
    """Lines of the X-macro ``name`` (commented ``what``) with one X(...) per row."""
    entries = [f"    X({', '.join(row)})" for row in rows]
    return [f"/* {what} */", f"#define {name}(X)"] + entries + [""] if not entries else \
        [f"/* {what} */", f"#define {name}(X) \\"] + \
        [entry + " \\" for entry in entries[:-1]] + [entries[-1], ""]


def parameter_table_header():
    """Text of ``sma_parameters_table.h``."""
    defaults = {f.name: f.default for f in dataclasses.fields(WireParameters) if f.init}
    fields = {name for _, name in _wire_fields()}
    terms = [name for name, _ in TERM_DEFAULTS]
    unknown = [name for name in terms if name not in {spec.name for spec in PARAMETER_SPECS}]
    if unknown:
        raise ValueError(f"TERM_DEFAULTS names {', '.join(unknown)}, not in PARAMETER_SPECS")
    earlier, term_rows = set(), []
    for name, default in TERM_DEFAULTS:
        if isinstance(default, str) and default not in earlier and default not in fields:
            raise ValueError(f"TERM_DEFAULTS: {name} falls back to {default}, neither a term "
                             f"above it nor a field of WireParameters")
        term_rows.append((name, _fallback(default, earlier)))
        earlier.add(name)
    specs = [(spec.name, f'"{spec.section}"', f'"{spec.unit}"', f"RULE_{spec.rule.upper()}",
              str(int(spec.required)), *(_number(float(end)) for end in spec.limits),
              f'"{range_text(spec)}"')
             for spec in PARAMETER_SPECS]
    given_defaults = [(spec.name, _number(defaults[spec.name])) for spec in PARAMETER_SPECS
                      if not spec.required and defaults[spec.name] is not None]
    lines = [
        "/* The wire parameter schema of the C family, generated when the C family is built from",
        " * sma_fmu/runtime/parameters.py (PARAMETER_SPECS, WireParameters) and model_terms.py",
        " * (TERM_DEFAULTS) by sma_fmu/fmi/packaging/parameter_table.py. Do not edit: change those.",
        " * Its order is PARAMETER_SPECS': the layout of values[] and of model_starts.json's",
        " * wire_defaults. Each list is an X-macro: X(...) once per entry. */",
        "#ifndef SMA_PARAMETERS_TABLE_H", "#define SMA_PARAMETERS_TABLE_H", "",
        f"#define DEFAULT_DEPTH {DEFAULT_DEPTH}               /* minor_loops.DEFAULT_DEPTH */",
        f"#define MAX_MEMORY_DEPTH {MAX_MEMORY_DEPTH}",
        f"#define DEFAULT_STRESS_MAX {_number(DEFAULT_STRESS_MAX)}      /* MPa */", "",
        *_list("SMA_PARAMETER_RULES", "X(rule, low end open, high end open): PARAMETER_SPECS' "
               "rules", [(f"RULE_{rule.upper()}", str(int(low)), str(int(high)))
                         for rule, (low, high) in RULES.items()]),
        *_list("SMA_PARAMETER_SPECS", "X(name, section, unit, rule, required, low, high, range "
               "text): every\n * parameter, in PARAMETER_SPECS order, with its plausible range",
               specs),
        *_list("SMA_PARAMETER_DEFAULTS", "X(name, value): the optional parameters that "
               "default to a number (the others to None: NaN)", given_defaults),
        *_list("SMA_WIRE_FIELDS", "X(C type, name): the parameters WireParameters holds as "
               "fields, in its order", _wire_fields()),
        *_list("SMA_MODEL_TERMS", "X(name, value in use when not given): the model terms, "
               "each an optional parameter\n * (ModelTerms' fields; an expression of "
               "p, the WireParameters, and t, the ModelTerms)", term_rows),
        "#endif", ""]
    return "\n".join(lines)


def generated_files():
    """{file name: text} of the C family's generated runtime headers."""
    return {TABLE_HEADER: parameter_table_header()}


def generated_folder():
    """A folder holding :func:`generated_files` (under the temporary folder, named by their
    content: written once, atomically, and shared by parallel builds); its Path."""
    files = generated_files()
    digest = hashlib.sha256()
    for name, text in sorted(files.items()):
        digest.update(name.encode() + b"\0" + text.encode("utf-8") + b"\0")
    folder = Path(tempfile.gettempdir()) / "sma-fmu-generated" / digest.hexdigest()[:24]
    folder.mkdir(parents=True, exist_ok=True)
    for name, text in files.items():
        path = folder / name
        if not path.is_file() or path.read_text(encoding="utf-8") != text:
            partial = folder / f".{name}.{os.getpid()}"
            partial.write_text(text, encoding="utf-8")
            os.replace(partial, path)
    return folder
