"""Study specs (TOML): base scenarios, overrides, axes and a Monte Carlo of the wire.

::

    [study]
    description = "Kp x Ki on the load-step scenario"
    scenarios = ["load-step-pi+ff-adaptive"]   # shipped names, or files relative to this one
    seed = 1                                    # seeds random and Latin-hypercube axes and draws
    # runs_per_task = 500                       # runs per Dask task (default: split evenly)

    [overrides]                                 # every run; keys as in sma_fmu.studies.overrides
    "scenario.stop_time_s" = 10.0

    [axes]
    kind = "grid"                               # grid | random | lhs (scipy.stats.qmc)
    # samples = 100                             # random, lhs: number of points
    [axes.values]                               # grid: a list, or {low, high, num, log}
    "controller.Kp_W_per_ohm" = [0.1, 0.3, 1.0] # random, lhs: {low, high, log}, or a list
    "controller.Ki_W_per_ohm_s" = { low = 0.25, high = 4.0, num = 5, log = true }

    [monte_carlo]                               # wire parameters ~ N(estimates, covariance)
    report = "fit/report.json"                  # of sma-fmu fit, relative to this file
    samples = 1000
    # parameters = ["a_h", "a_c"]               # default: every parameter in the report
    # apply_to = ["wire"]                       # the plant's wire (default); add "model" for
                                                # a compensator identified on each wire

Runs: every base scenario x every axis point x every draw. Problems raise
:class:`~sma_fmu.studies.overrides.StudyError` naming the file, the key and the value.
"""
import functools
import hashlib
import itertools
import json
from dataclasses import dataclass
from pathlib import Path

from sma_fmu.cosim.scenario import ScenarioError, check_sections
from sma_fmu.studies.design import MAX_POINTS, axis_points, monte_carlo_draws
from sma_fmu.studies.overrides import StudyError, template
from sma_fmu.files.toml_files import read_toml

__all__ = ["AXIS_KINDS", "StudyRunSpec", "StudySpec", "load_spec"]

AXIS_KINDS = ("grid", "random", "lhs")
_SECTIONS = {"study": {"description", "scenarios", "seed", "runs_per_task"},
             "overrides": None, "axes": {"kind", "samples", "values"},
             "monte_carlo": {"report", "samples", "parameters", "apply_to"}}
APPLY_TO = ("wire", "model")


@dataclass(frozen=True)
class StudyRunSpec:
    """One run of a study: its id, base scenario (index into the templates), overrides, and
    the axis point and Monte Carlo draw it comes from (None where the study has none)."""

    run_id: int
    base: int
    overrides: dict
    point: object = None
    draw: object = None


@dataclass
class StudySpec:
    """A validated study spec; :meth:`runs` lists its runs (built once: a spec is not
    changed after :func:`load_spec`)."""

    path: Path
    description: str
    templates: list
    overrides: dict
    axes_kind: str
    axes: dict                    # key -> list of values (grid) or sampled values
    points: list                  # [{key: value}] of the axes
    draws: list                   # [{"wire.NAME": value}] of the Monte Carlo
    seed: int
    runs_per_task: object
    report: object = None

    @property
    def inputs(self):
        """Names of the varied inputs: the axes' keys, then the drawn wire parameters."""
        return list(self.axes) + (list(self.draws[0]) if self.draws else [])

    def runs(self):
        """Every :class:`StudyRunSpec`, in a fixed order (ids 0, 1, ...), as a tuple."""
        return self._runs

    @functools.cached_property
    def _runs(self):
        points = self.points or [{}]
        draws = self.draws or [{}]
        out = []
        for base, (p_index, point), (d_index, draw) in itertools.product(
                range(len(self.templates)), enumerate(points), enumerate(draws)):
            out.append(StudyRunSpec(len(out), base, {**self.overrides, **point, **draw},
                                    p_index if self.points else None,
                                    d_index if self.draws else None))
        return tuple(out)

    def fingerprint(self):
        """A hash of everything that decides the runs: resuming needs the same one."""
        document = {"templates": [[t.name, t.document, t.parameter_set.params.values()]
                                  for t in self.templates],
                    "runs": [[r.base, r.overrides] for r in self.runs()]}
        text = json.dumps(document, sort_keys=True, default=repr)
        return hashlib.sha256(text.encode("utf-8")).hexdigest()


def _fail(path, message):
    raise StudyError(f"{path}: {message}")


def _integer(path, where, value, low=0):
    if isinstance(value, bool) or not isinstance(value, int) or value < low:
        _fail(path, f"{where} must be a whole number >= {low}, got {value!r}")
    return value


def _templates(path, names):
    if not isinstance(names, list) or not names or not all(isinstance(n, str) for n in names):
        _fail(path, f"[study] scenarios must be a non-empty list of names or files, got {names!r}")
    templates = []
    for name in names:
        relative = path.parent / name
        try:
            templates.append(template(relative if relative.is_file() else name))
        except ScenarioError as error:
            _fail(path, f"[study] scenarios: {error}")
    return templates


def load_spec(path):
    """Read and check a study spec; draws its axes and Monte Carlo. Returns a :class:`StudySpec`."""
    path = Path(path)
    document = read_toml(path, StudyError, "study spec")
    check_sections(path, document, _SECTIONS, ("study",), StudyError)
    head = document["study"]
    seed = _integer(path, "[study] seed", head.get("seed", 0))
    per_task = head.get("runs_per_task")
    if per_task is not None:
        _integer(path, "[study] runs_per_task", per_task, low=1)
    templates = _templates(path, head.get("scenarios"))
    overrides = dict(document.get("overrides", {}))
    axes = document.get("axes", {})
    kind = axes.get("kind", "grid")
    if kind not in AXIS_KINDS:
        _fail(path, f"[axes] kind must be one of {', '.join(AXIS_KINDS)}, got {kind!r}")
    try:
        values, points = axis_points(kind, axes.get("values", {}), axes.get("samples"), seed)
    except ValueError as error:
        _fail(path, f"[axes] {error}")
    report, draws = None, []
    if "monte_carlo" in document:
        mc = document["monte_carlo"]
        if "report" not in mc or not isinstance(mc["report"], str):
            _fail(path, "[monte_carlo] report must name the report.json of sma-fmu fit")
        report = path.parent / mc["report"]
        samples = _integer(path, "[monte_carlo] samples", mc.get("samples", 100), low=1)
        if samples > MAX_POINTS:
            _fail(path, f"[monte_carlo] samples = {samples} exceeds the limit of {MAX_POINTS}")
        targets = mc.get("apply_to", ["wire"])
        if not isinstance(targets, list) or not targets or set(targets) - set(APPLY_TO):
            _fail(path, f"[monte_carlo] apply_to must be a list of {' and '.join(APPLY_TO)}, "
                        f"got {targets!r}")
        try:
            drawn = monte_carlo_draws(report, samples, mc.get("parameters"), seed)
        except ValueError as error:
            _fail(path, f"[monte_carlo] {error}")
        draws = [{f"{target}.{name}": value for target in targets for name, value in d.items()}
                 for d in drawn]
    total = len(templates) * max(1, len(points)) * max(1, len(draws))
    if total > MAX_POINTS:
        _fail(path, f"the study has {total} runs ({len(templates)} scenarios x "
                    f"{max(1, len(points))} points x {max(1, len(draws))} draws); at most "
                    f"{MAX_POINTS} are allowed")
    spec = StudySpec(path, str(head.get("description", "")), templates, overrides, kind, values,
                     points, draws, seed, per_task, report)
    _check_first_runs(spec)
    return spec


def _check_first_runs(spec):
    """Build the first run of each base scenario now, so a bad override fails before any run."""
    drawn = set(spec.draws[0]) if spec.draws else set()   # a draw may fail: one run's fate
    runs = spec.runs()
    for run in runs[::len(runs) // len(spec.templates)]:  # runs are base-major
        fixed = {k: v for k, v in run.overrides.items() if k not in drawn}
        spec.templates[run.base].scenario(fixed)
