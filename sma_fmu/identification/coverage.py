"""What a fit's data covered and what it did not determine, for identified.toml and report.json.

Every fit writes a complete parameter file, but its data say nothing about most of it. This
module says which part:

- :func:`data_range`: the temperatures and stresses the data covered, the file's optional
  ``validity.T_data_min`` ... ``stress_data_max`` (the FMUs warn once when a run leaves
  them). With a base file that has a range already (a fit completing another fit's file)
  the range is the overlap of both: where every part of the file was identified.
- :func:`coverage`: that range, the diameter that turned stress into load (MPa <-> kg) and
  the parameters taken from the base file, "not identified here", by section;
  :func:`coverage_lines`: the same for the console, :func:`coverage_header` for the file;
- :func:`with_coverage`: both at once, what a fit's runner calls.
"""
import math
from pathlib import Path

from sma_fmu.runtime.constant_load import branch_constants, branch_fractions
from sma_fmu.runtime.constants import COOLING, HEATING, STANDARD_GRAVITY
from sma_fmu.runtime.model_terms import TERM_DEFAULTS
from sma_fmu.runtime.parameters import DATA_RANGE, PARAMETER_SPECS

__all__ = ["DATA_RANGE_MEANINGS", "data_range", "stress_of_load", "coverage", "coverage_lines",
           "with_coverage", "coverage_header"]

DATA_RANGE_MEANINGS = {
    "T_data_min": "lowest temperature of the data this file was fitted to (a warning below it)",
    "T_data_max": "highest temperature of the data this file was fitted to (a warning above it)",
    "stress_data_min": "lowest stress of the data this file was fitted to (a warning below it)",
    "stress_data_max": "highest stress of the data this file was fitted to (a warning above it)",
}
_SETTINGS = ("validity",)   # sections a fit sets itself (the range, the physical limits)
_TERMS = {name for name, default in TERM_DEFAULTS if isinstance(default, float)}  # a number
DONE_SHARE = 0.99   # a transformation this far done counts as done (share_done)


def stress_of_load(load, diameter):
    """Tensile stress [MPa] of ``load`` [kg] on a wire of ``diameter`` [m]."""
    return STANDARD_GRAVITY * load / (math.pi * diameter * diameter / 4.0) / 1e6


def _outward(low, high):
    """(low, high) rounded outward to 0.1 (of degC or MPa)."""
    return math.floor(low * 10.0) / 10.0, math.ceil(high * 10.0) / 10.0


def data_range(temperatures, stresses, base):
    """({T_data_min, T_data_max [degC], stress_data_min, stress_data_max [MPa]}, note).

    ``temperatures`` [degC] and ``stresses`` [MPa]: every value the data hold (iterables);
    ``base``: the base file's WireParameters. Its own range, where it has one, narrows this
    one (the overlap); where the two do not overlap the data's own range stands and
    ``note`` says so ("" otherwise)."""
    temperatures, stresses = [float(t) for t in temperatures], [float(s) for s in stresses]
    found = dict(zip(("T_data_min", "T_data_max"), _outward(min(temperatures), max(temperatures))))
    found.update(zip(("stress_data_min", "stress_data_max"), _outward(min(stresses), max(stresses))))
    notes = []
    for low, high, unit in (("T_data_min", "T_data_max", "degC"),
                            ("stress_data_min", "stress_data_max", "MPa")):
        old_low, old_high = getattr(base, low), getattr(base, high)
        if old_low is None and old_high is None:
            continue
        new_low = found[low] if old_low is None else max(found[low], old_low)
        new_high = found[high] if old_high is None else min(found[high], old_high)
        if new_low <= new_high:
            found[low], found[high] = new_low, new_high
        else:
            notes.append(f"the base file's {low}..{high} {old_low}..{old_high} {unit} and "
                         f"these data's do not overlap: the range is these data's")
    return found, "; ".join(notes)


def coverage(params, base_set, fitted, note=""):
    """The JSON-ready coverage of a fit: {"data_range", "data_range_note", "ambient_note"
    (why a run at the file's T_room warns, or ""), "stress_conversion", "not_identified_here"}.

    ``params``: the fitted WireParameters (the range already in it), ``base_set``: the base
    file's ParameterSet, ``fitted``: the names the fit determined. A parameter is "not
    identified here" when it was not fitted and keeps the base file's value (the validity
    section is the fit's own: its range and the physical limits); so is an optional term the
    file omits in a section it uses (T_alpha beside a fitted alpha_P), with the value in
    use, named in "defaults"."""
    base = base_set.params
    given = {spec.section for spec in PARAMETER_SPECS if getattr(params, spec.name) is not None}
    taken, defaults = {}, []
    for spec in PARAMETER_SPECS:
        value = getattr(params, spec.name)
        if spec.name in fitted or spec.section in _SETTINGS:
            continue
        if value is None and spec.name in _TERMS and spec.section in given:
            value = getattr(params.terms, spec.name)   # a term of a section in use: its default
            defaults.append(spec.name)
        if value is None or (spec.name not in defaults and value != getattr(base, spec.name)):
            continue
        taken.setdefault(spec.section, {})[spec.name] = value
    name = Path(str(base_set.path)).name if base_set.path is not None else base_set.name
    return {
        "data_range": {key: getattr(params, key) for key in DATA_RANGE},
        "data_range_note": note,
        "ambient_note": "; ".join(note for note in (_ambient_note(params), _cooling_note(params))
                                  if note),
        "stress_conversion": {
            "diameter_m": params.diameter,
            "source": f"geometry.diameter of {name}",
            "kg_per_MPa": 1.0 / stress_of_load(1.0, params.diameter),
            "note": "load [kg] = stress [MPa] x 1e6 x pi d^2/4 / g: every stress of this fit "
                    "was turned into a load, and back, on this diameter"},
        "not_identified_here": {"base_file": str(base_set.path), "by_section": taken,
                                "defaults": defaults},
    }


def _ambient_note(params):
    """Why a run at the file's own ambient T_room warns, if it does ("" otherwise): a run
    starts at T_room, so below T_data_min every run of this wire warns at its start."""
    low, high, ambient = params.T_data_min, params.T_data_max, params.T_room
    if low is not None and ambient < low:
        side = f"below the data's range (T_data_min = {low:g} degC)"
    elif high is not None and ambient > high:
        side = f"above the data's range (T_data_max = {high:g} degC)"
    else:
        return ""
    return (f"thermal.T_room = {ambient:g} degC is {side}: a run at this ambient starts "
            f"outside it and warns; set thermal.T_room to your lab's ambient")


def share_done(temperature, load, direction, params):
    """How far [1] the model's major-branch transformation of ``direction`` (+1/-1) is done at
    ``temperature`` [degC] and ``load`` [kg]: the share of M gone to austenite on heating,
    come to martensite on cooling."""
    constants = branch_constants(load, direction, params)
    share = branch_fractions(temperature, constants)[0] / constants.M if constants.M else 1.0
    return 1.0 - share if direction == HEATING else share


def _cooling_note(params):
    """Why a heated wire of this fit does not cool back at its ambient ("" when it does): at
    the data's lowest load, where the cooling transformation lies coldest, the model's is
    less than :data:`DONE_SHARE` complete at T_room, so passive cooling returns a wire
    heated through it only part of the way (runs warn: ``above_ambient_fraction``)."""
    if params.load_data_min is None:
        return ""
    share = share_done(params.T_room, params.load_data_min, COOLING, params)
    if share >= DONE_SHARE:
        return ""
    return (f"at {params.stress_data_min:g} MPa the model's cooling transformation is only "
            f"{100.0 * share:.0f} % complete at thermal.T_room = {params.T_room:g} degC: "
            f"passive cooling to that ambient returns a heated wire only that far, and runs "
            f"asking for more warn; set thermal.T_room to your bench's ambient")


def coverage_lines(report):
    """Console lines of a fit report's ``coverage`` (:func:`coverage`)."""
    part = report["coverage"]
    span, conversion = part["data_range"], part["stress_conversion"]
    shown = {key: "-" if value is None else f"{value:g}" for key, value in span.items()}
    lines = [f"data range: {shown['T_data_min']} .. {shown['T_data_max']} degC, "
             f"{shown['stress_data_min']} .. {shown['stress_data_max']} MPa "
             f"(validity.T_data_*, stress_data_*: the FMUs warn once outside it)"]
    if part["data_range_note"]:
        lines.append(f"data range: {part['data_range_note']}")
    if part.get("ambient_note"):
        lines.append(f"note: {part['ambient_note']}")
    lines.append(f"MPa <-> kg on a {conversion['diameter_m'] * 1e3:g} mm wire "
                 f"({conversion['source']}): 1 MPa = {conversion['kg_per_MPa']:.4g} kg")
    taken = part["not_identified_here"]
    lines.append(f"not identified here (kept from {Path(taken['base_file']).name}):")
    lines += [f"  [{section}] " + ", ".join(
        f"{name} (default {value:g})" if name in taken["defaults"] else name
        for name, value in names.items()) for section, names in taken["by_section"].items()]
    return lines


def with_coverage(params, base_set, fitted, temperatures, stresses):
    """(``params`` with the data range of ``temperatures`` [degC] and ``stresses`` [MPa],
    its :func:`coverage`): what a fit's runner calls before it writes identified.toml.
    ``temperatures`` None: the data do not bear on the FMUs' range (it stays as given)."""
    if temperatures is None:
        return params, coverage(params, base_set, fitted, "these data (a model the FMUs do "
                                "not run) leave the base file's range as it was")
    found, note = data_range(temperatures, stresses, base_set.params)
    params = params.replace(**found)
    return params, coverage(params, base_set, fitted, note)


def coverage_header(covered):
    """The identified.toml comment line naming what the fit did not determine."""
    taken = covered["not_identified_here"]
    names = [name for entries in taken["by_section"].values() for name in entries]
    diameter = covered["stress_conversion"]["diameter_m"]
    return (f"Not identified here (kept from {Path(taken['base_file']).name}): "
            f"{', '.join(names)}. Stress <-> load on its {diameter * 1e3:g} mm diameter.")
