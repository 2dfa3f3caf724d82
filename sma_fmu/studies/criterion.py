"""What ``sma-fmu tune`` minimises: the RMSE of R - R_ref [ohm], or of the stroke [um].

A stroke scenario (``[reference] quantity = "stroke"``) is controlled through R, but what its
user wants is the stroke: gains tuned on R are not those that track the stroke best (the R
the map asks for is on the major branch, the wire often is not). So its default criterion is
``"stroke"``, the RMSE of (x_0 - x) - stroke_ref over the metrics window [um] (the
``stroke`` record of the run's metrics); ``"resistance"`` keeps R's. Any other scenario has
only ``"resistance"``. The records of a stroke scenario name their criterion and give the
stroke's and R's numbers side by side (:func:`stroke_fields`, :func:`stroke_markdown`); a
resistance scenario's records are as they always were.
"""
import math

from sma_fmu.studies.overrides import StudyError
from sma_fmu.runtime.signals import is_stroke

__all__ = ["CRITERIA", "UNITS", "scenario_criterion", "criterion_rmse",
           "stroke_fields", "stroke_markdown"]

CRITERIA = ("stroke", "resistance")
UNITS = {"resistance": "ohm", "stroke": "um"}
_FAILED = {"resistance": 1e6, "stroke": 1e9}   # what a failed run costs: [ohm], [um] (1 km)


def scenario_criterion(scenario, chosen=None):
    """The criterion ``scenario`` is tuned on: ``chosen`` (one of :data:`CRITERIA`), or
    None for its default ("stroke" for a stroke scenario, else "resistance"). Raises
    :class:`StudyError` for "stroke" on a resistance scenario."""
    if chosen is None:
        return "stroke" if is_stroke(scenario.reference) else "resistance"
    if chosen not in CRITERIA:
        raise StudyError(f"--criterion {chosen!r}: must be one of {', '.join(CRITERIA)}")
    if chosen == "stroke" and not is_stroke(scenario.reference):
        raise StudyError(f"--criterion stroke: scenario {scenario.name}'s reference is a "
                         "resistance, not a stroke")
    return chosen


def criterion_rmse(metrics, criterion):
    """The run's RMSE in the criterion's unit (:data:`UNITS`); a failed run's (``metrics``
    None, or no finite RMSE) costs :data:`_FAILED`."""
    if metrics is None:
        value = None
    elif criterion == "stroke":
        value = metrics.get("stroke", {}).get("rmse_um")
    else:
        value = metrics["overall"]["rmse_ohm"]
    return _FAILED[criterion] if value is None or not math.isfinite(value) else value


def stroke_fields(criterion, tuned, given, objective):
    """A stroke scenario's record fields: the criterion and both RMSEs, library path.

    ``tuned`` and ``given`` are the metrics at the tuned and the given gains; ``objective``
    is the optimiser's best value (the batch's, in the criterion's unit)."""
    fields = {"criterion": criterion, "unit": UNITS[criterion],
              "rmse_um": {"tuned": tuned["stroke"]["rmse_um"], "given": given["stroke"]["rmse_um"]},
              "rmse_ohm": {"tuned": tuned["overall"]["rmse_ohm"],
                           "given": given["overall"]["rmse_ohm"]}}
    fields[f"rmse_{UNITS[criterion]}"]["tuned_batch"] = objective
    return fields


def _score(record, key):
    robust = record.get("robust")
    if not robust:
        return "-"
    unit = UNITS[record["criterion"]]
    return f"{robust[f'score_{key}_{unit}']:.4g} {'µm' if unit == 'um' else 'Ω'}"


def stroke_markdown(records):
    """The table of the stroke scenarios' records (empty when there is none)."""
    records = [record for record in records if "criterion" in record]
    if not records:
        return []
    lines = ["", "## Stroke scenarios", "",
             "Tuned on the criterion named (`stroke`: the stroke's RMSE [µm]; `resistance`: "
             "R's [Ω]); both RMSEs over the metrics window, on the library path; the score "
             "(with `--robust`) in the criterion's unit.", "",
             "| scenario | criterion | stroke RMSE given [µm] | stroke RMSE tuned [µm] | "
             "RMSE given [Ω] | RMSE tuned [Ω] | score given | score tuned | tuned values "
             "(* at a bound) | gain margin [dB] | phase margin [deg] |",
             "|---|---|---:|---:|---:|---:|---:|---:|---|---:|---:|"]
    for record in records:
        values = ", ".join(f"{name} = {value:.4g}{'*' if name in record['at_bound'] else ''}"
                           for name, value in record["tuned"].items())
        margins = record["margins"]["tuned"]
        lines.append(f"| {record['scenario']} | {record['criterion']} | "
                     f"{record['rmse_um']['given']:.1f} | {record['rmse_um']['tuned']:.1f} | "
                     f"{record['rmse_ohm']['given']:.3f} | {record['rmse_ohm']['tuned']:.3f} | "
                     f"{_score(record, 'given')} | {_score(record, 'tuned')} | {values} | "
                     f"{margins['gain_margin_dB']:.1f} | {margins['phase_margin_deg']:.1f} |")
    return lines
