"""Read and write wire parameter files (TOML, every entry with value, unit and meaning).

A parameter file looks like ``sma_fmu/models/reference_wire.toml``::

    [wire]
    name = "reference"
    description = "..."

    [geometry]
    x0 = { value = 0.800, unit = "m", meaning = "length at low temperature, never loaded" }

Sections and keys follow :data:`sma_fmu.runtime.parameters.PARAMETER_SPECS`; unknown or
missing keys, wrong units, non-numbers and values breaking a rule raise
:class:`ParameterError` naming the file, the key and the value.
"""
import json
from dataclasses import dataclass, field
from pathlib import Path

from sma_fmu.files.package_data import default_parameter_file
from sma_fmu.runtime.constant_load import branch_constants
from sma_fmu.runtime.constants import COOLING, HEATING
from sma_fmu.runtime.parameters import PARAMETER_SPECS, ParameterError, WireParameters
from sma_fmu.runtime.wire_identity import wire_digest
from sma_fmu.files.toml_files import read_toml
from sma_fmu.wire.geometry import DERIVABLE, GEOMETRY_INPUTS, complete_from_geometry

__all__ = ["ParameterSet", "load_parameter_set", "load_parameters", "parse_parameter_document",
           "parameter_file_text", "write_parameter_file", "ParameterError"]

_ENTRY_FIELDS = {"value", "unit", "meaning"}
_FILE_SPECS = PARAMETER_SPECS + GEOMETRY_INPUTS  # what a file may hold
_SECTIONS = {spec.section for spec in _FILE_SPECS}


@dataclass(frozen=True)
class ParameterSet:
    """A parameter file's content: the validated parameters plus their descriptions."""

    params: WireParameters
    name: str
    description: str
    meanings: dict = field(default_factory=dict)
    path: Path = None
    derived: dict = field(default_factory=dict)  # {name: how it was derived} (wire_geometry)

    @property
    def digest(self):
        """The wire's identity, ``"sha256:..."`` of its canonical values
        (:func:`~sma_fmu.runtime.wire_identity.wire_digest`)."""
        return wire_digest(self.params)

    def record(self):
        """{"file": the parameter file's path (or None), "digest": :attr:`digest`}: how a run
        names the wire it ran."""
        return {"file": None if self.path is None else str(self.path), "digest": self.digest}

    def as_json(self):
        """JSON-ready dict {name, description, wire_digest, parameters: {key: {value, unit,
        meaning}}}."""
        return {
            "name": self.name,
            "description": self.description,
            "wire_digest": self.digest,
            "parameters": {
                spec.name: {"value": getattr(self.params, spec.name), "unit": spec.unit,
                            "meaning": self.meanings.get(spec.name, "")}
                for spec in PARAMETER_SPECS if getattr(self.params, spec.name) is not None
            },
        }


def parse_parameter_document(document, source):
    """Validate a parsed TOML document and return a :class:`ParameterSet`."""
    wire = document.get("wire", {})
    if not isinstance(wire, dict):
        raise ParameterError(f"{source}: [wire] must be a table")
    unknown_sections = sorted(set(document) - _SECTIONS - {"wire"})
    if unknown_sections:
        raise ParameterError(f"{source}: unknown section(s) {', '.join(unknown_sections)}; "
                             f"expected {', '.join(sorted(_SECTIONS | {'wire'}))}")
    values, meanings = {}, {}
    specs_by_section = {}
    for spec in _FILE_SPECS:
        specs_by_section.setdefault(spec.section, {})[spec.name] = spec
    for section, entries in document.items():
        if section == "wire":
            continue
        if not isinstance(entries, dict):
            raise ParameterError(f"{source}: [{section}] must be a table")
        for key, entry in entries.items():
            spec = specs_by_section[section].get(key)
            if spec is None:
                raise ParameterError(f"{source}: unknown parameter {section}.{key}; expected one "
                                     f"of {', '.join(specs_by_section[section])}")
            values[key], meanings[key] = _parse_entry(entry, spec, source)
    missing = [f"{s.section}.{s.name}" for s in PARAMETER_SPECS
               if s.required and s.name not in values and s.name not in DERIVABLE]
    if missing:
        raise ParameterError(f"{source}: missing parameter(s) {', '.join(missing)}")
    values, derived = complete_from_geometry(values, source)
    params = WireParameters.from_values(values, source=str(source))
    check_load_range(params, source)
    return ParameterSet(params, str(wire.get("name", Path(str(source)).stem)),
                        str(wire.get("description", "")), meanings, derived=derived)


def check_load_range(params, source):
    """Raise :class:`ParameterError` naming ``source`` and the parameters behind it when the
    major branches cannot be evaluated at load 0 or at the validity limit ``load_max``.

    Each value may pass its own rule while together they put the model out of the
    floating-point range (``geometry.mass = 5e-324`` makes N tiny and dH(f) overflow at any
    load): say so when the file is read, not at the first step of a run.
    """
    for load in (0.0, params.load_max):
        for direction in (HEATING, COOLING):
            try:
                branch_constants(load, direction, params)
            except ValueError as error:
                raise ParameterError(
                    f"{source}: the model cannot be evaluated at load {load!r} kg, within its "
                    f"validity range [0, {params.load_max!r}] kg: {error}. It follows from "
                    f"dH(f) = nu (eps_T - g f x_T / N) with constant_load.nu = {params.nu!r}, "
                    f"constant_load.eps_T = {params.eps_T!r} J, x_T = {params.x_T!r} m "
                    f"(phases.l_M, phases.l_F, geometry.x_min) and N = {params.N!r} "
                    f"(geometry.mass = {params.mass!r} kg, x0, diameter, theta), and the "
                    f"centres hysteresis.a_h + b_h f, a_c + b_c f{_terms_note(params)}") from None


def _terms_note(params):
    """What the optional model terms add to the range of the model (empty when they are off)."""
    terms, parts = params.terms, []
    if terms.nu_h != params.nu or terms.nu_c != params.nu:
        parts.append(f"constant_load.nu_h = {terms.nu_h!r}, nu_c = {terms.nu_c!r} in place of nu")
    if terms.cc_share_h != 0.0 or terms.cc_share_c != 0.0:
        parts.append(f"the strain-weighted load f_d in place of f (hysteresis.cc_share_h = "
                     f"{terms.cc_share_h!r}, cc_share_c = {terms.cc_share_c!r})")
    if terms.two_stage:
        parts.append(f"the second stage's centres second_stage.a2_h + b2_h f, a2_c + b2_c f "
                     f"and nu2_h = {terms.nu2_h!r}, nu2_c = {terms.nu2_c!r}")
    return "; with " + " and ".join(parts) if parts else ""


def _parse_entry(entry, spec, source):
    key = f"{spec.section}.{spec.name}"
    if not isinstance(entry, dict):
        raise ParameterError(f"{source}: parameter {key} must be a table "
                             f"{{ value = ..., unit = \"{spec.unit}\", meaning = \"...\" }}, got {entry!r}")
    extra = sorted(set(entry) - _ENTRY_FIELDS)
    if extra:
        raise ParameterError(f"{source}: parameter {key} has unknown field(s) {', '.join(extra)}")
    for name in ("value", "unit"):
        if name not in entry:
            raise ParameterError(f"{source}: parameter {key} has no {name}")
    if entry["unit"] != spec.unit:
        raise ParameterError(f"{source}: parameter {key} has unit {entry['unit']!r}; "
                             f"expected {spec.unit!r}")
    value = entry["value"]
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ParameterError(f"{source}: parameter {key} value must be a number "
                             f"[{spec.unit}], got {value!r}")
    return float(value), str(entry.get("meaning", ""))


def load_parameter_set(path=None):
    """Load a parameter file (default: the reference wire) as a :class:`ParameterSet`."""
    path = Path(path) if path is not None else default_parameter_file()
    document = read_toml(path, ParameterError, "parameter file")
    parsed = parse_parameter_document(document, path)
    return ParameterSet(parsed.params, parsed.name, parsed.description, parsed.meanings, path,
                        parsed.derived)


def load_parameters(path=None):
    """Load only the :class:`WireParameters` of a parameter file (default: the reference wire)."""
    return load_parameter_set(path).params


def parameter_file_text(params, name, description="", meanings=None, header=()):
    """``params`` as the text of a parameter file in the format of ``models/``.

    ``meanings`` maps parameter names to one-line meanings; ``header`` lines become comments.
    Values are written with full precision (``repr``) so the file reloads exactly.
    """
    meanings = meanings or {}
    lines = [f"# {line}" for line in header]
    lines += ["", "[wire]", f"name = {json.dumps(name)}",
              f"description = {json.dumps(description)}"]
    section = None
    for spec in PARAMETER_SPECS:
        value = getattr(params, spec.name)
        if value is None:
            continue
        if spec.section != section:
            section = spec.section
            lines += ["", f"[{section}]"]
        rendered = repr(value) if spec.rule == "depth" else repr(float(value))
        lines.append(f"{spec.name} = {{ value = {rendered}, unit = {json.dumps(spec.unit)}, "
                     f"meaning = {json.dumps(meanings.get(spec.name, ''))} }}")
    return "\n".join(lines) + "\n"


def write_parameter_file(path, params, name, description="", meanings=None, header=()):
    """Write :func:`parameter_file_text` to ``path``; returns the path."""
    path = Path(path)
    path.write_text(parameter_file_text(params, name, description, meanings, header), encoding="utf-8")
    return path
