"""The optional model terms on an FMU's page: each term's equations with the wire's numbers
when it is on, one line naming it as off when it is not, and the inverse's method.

:data:`TERM_PAGES` is the table, one :class:`TermPage` per term, in the order the page shows
them; a new term of the model is one entry. The models' pages (``page.html``) take the
rendered table as ``${terms}`` and the compensator's inverse as ``${inverse}``
(:func:`page_blocks`). A number is written by :func:`field`, as the pages' other numbers
are: ``<span class="limit" data-name="name" data-value="repr">value unit</span>``; each term
is a ``<section class="term" data-term="key" data-state="on|off">``, so a reader sees what
runs and a test can read it back.
"""
import html
import math
from collections import namedtuple
from string import Template

from sma_fmu.runtime.parameters import SPEC_BY_NAME
from sma_fmu.runtime.sensing import inverse_method

__all__ = ["TermPage", "TERM_PAGES", "field", "terms_html", "inverse_html", "data_range_html",
           "page_blocks"]

TermPage = namedtuple("TermPage", ["key", "title", "active", "numbers", "equations", "off"])
TermPage.__doc__ = """One optional term of the model on the page.

key : its name in the HTML (``data-term``); title : its heading;
active(params) -> bool : whether the wire ``params`` (WireParameters) switches it on;
numbers : the parameters its text quotes, each ``${name}`` in ``equations`` and ``off``
(the value in use: ``params.terms`` for a model term, else ``params``; unit from
PARAMETER_SPECS); equations : the HTML shown when it is on; off : the HTML shown when off.
"""

_UNITS = {"degC": "°C", "degC/kg": "°C/kg", "1": "", "MPa": "MPa", "1/K": "1/K"}


def field(name, value, unit):
    """A number of the page: its value and unit, with its exact value for a reader program."""
    shown = f"{value:.4g}" if math.isfinite(value) else repr(value)
    return (f'<span class="limit" data-name="{html.escape(name)}" data-value="{value!r}">'
            f"{html.escape(shown)}{' ' if unit else ''}{html.escape(unit)}</span>")


TERM_PAGES = (
    TermPage(
        "widths", "Domain sizes on heating and cooling",
        lambda p: p.nu_h is not None or p.nu_c is not None,
        ("nu", "nu_h", "nu_c"),
        '<p class="eq">ΔH<sub>d</sub>(f) = ν<sub>d</sub> (ε<sub>T</sub> − g f x<sub>T</sub>/N) [J], '
        '&nbsp; ν<sub>h</sub> = ${nu_h} (heating), &nbsp; ν<sub>c</sub> = ${nu_c} (cooling)</p>\n'
        "<p>ΔH above is ΔH<sub>d</sub> of the direction d: the two transitions have their own "
        "widths (10–90 %: 2 ln 9 k<sub>B</sub> τ<sub>K</sub><sup>2</sup>/ΔH<sub>d</sub>). They "
        "replace the parameter <code>nu</code> (${nu}), which gives a width the file omits.</p>",
        "one domain size ν = ${nu} in both directions (<code>nu_h</code>, <code>nu_c</code> "
        "not given)"),
    TermPage(
        "second_stage", "Second transformation stage",
        lambda p: p.terms.two_stage,
        ("w2", "a2_h", "b2_h", "a2_c", "b2_c", "nu2_h", "nu2_c"),
        "<p>A share w<sub>2</sub> = ${w2} of the transformable fraction M transforms in a second "
        "logistic stage with its own centres and domain sizes; the major branch is</p>\n"
        '<p class="eq">ξ<sub>MF</sub> = M (1 − w<sub>2</sub>)/(1 + e<sup>Λ<sub>1</sub></sup>) '
        "+ M w<sub>2</sub>/(1 + e<sup>Λ<sub>2</sub></sup>), &nbsp; ξ<sub>P</sub> = M − "
        "ξ<sub>MF</sub> [1]</p>\n"
        '<p class="eq">Λ<sub>1</sub> = Λ above; &nbsp; Λ<sub>2</sub> = (ΔH<sub>2</sub>/k<sub>B</sub>)'
        "(1/τ<sub>2,K</sub> − 1/T<sub>K</sub>), &nbsp; ΔH<sub>2</sub> = ν<sub>2,d</sub> "
        "(ε<sub>T</sub> − g f x<sub>T</sub>/N) [J]</p>\n"
        '<p class="eq">τ<sub>2</sub> = ${a2_h} + ${b2_h} · f (heating), &nbsp; '
        "τ<sub>2</sub> = ${a2_c} + ${b2_c} · f (cooling); &nbsp; ν<sub>2,h</sub> = ${nu2_h}, "
        "&nbsp; ν<sub>2,c</sub> = ${nu2_c}</p>\n"
        "<p>R and x take ξ<sub>MF</sub> and ξ<sub>P</sub> of both stages together; minor loops "
        "scale this branch as they scale a one-stage one.</p>",
        "w<sub>2</sub> = ${w2}: one logistic stage"),
    TermPage(
        "thermal_expansion", "Thermal expansion",
        lambda p: p.terms.alpha_P != 0.0 or p.terms.alpha_MF != 0.0,
        ("alpha_P", "alpha_MF", "T_alpha"),
        '<p class="eq">ℓ<sub>P</sub>(T) = ℓ<sub>P</sub> (1 + α<sub>P</sub> (T − T<sub>α</sub>)), '
        "&nbsp; ℓ<sub>i</sub>(T, f) = ℓ<sub>i</sub>(f) (1 + α<sub>MF</sub> (T − T<sub>α</sub>)), "
        "i = M, F [m]</p>\n"
        '<p class="eq">α<sub>P</sub> = ${alpha_P}, &nbsp; α<sub>MF</sub> = ${alpha_MF}, &nbsp; '
        "T<sub>α</sub> = ${T_alpha}: where ℓ<sub>P</sub>, ℓ<sub>M</sub>, ℓ<sub>F</sub> are the "
        "given lengths</p>\n"
        "<p>x = ℓ<sub>P</sub>(T) ξ<sub>P</sub> + ℓ<sub>M</sub>(T, f) ξ<sub>M</sub> + "
        "ℓ<sub>F</sub>(T, f) ξ<sub>F</sub> [m] in place of the lengths above.</p>",
        "α<sub>P</sub> = ${alpha_P}, α<sub>MF</sub> = ${alpha_MF}: the phase lengths do not "
        "depend on T"),
    TermPage(
        "stress_law", "Stress law of the transformation strain",
        lambda p: p.terms.span_ratio_0 != 1.0 or p.terms.span_ratio_sat != 1.0,
        ("span_ratio_0", "span_ratio_sat", "span_stress"),
        '<p class="eq">s(σ) = s<sub>sat</sub> + (s<sub>0</sub> − s<sub>sat</sub>) '
        "e<sup>−σ/σ<sub>s</sub></sup> [1], &nbsp; σ = g f/(π d<sup>2</sup>/4) in MPa</p>\n"
        '<p class="eq">ℓ<sub>i</sub>(f) = ℓ<sub>P</sub> + s(σ) (ℓ<sub>i</sub> − ℓ<sub>P</sub>), '
        "i = M, F [m]</p>\n"
        '<p class="eq">s<sub>0</sub> = ${span_ratio_0}, &nbsp; s<sub>sat</sub> = '
        "${span_ratio_sat}, &nbsp; σ<sub>s</sub> = ${span_stress}</p>\n"
        "<p>The transformation strain, the phases' length deviations from ℓ<sub>P</sub>, "
        "scales with the stress (Lagoudas' H<sub>cur</sub> form).</p>",
        "s<sub>0</sub> = ${span_ratio_0}, s<sub>sat</sub> = ${span_ratio_sat}: ℓ<sub>M</sub>, "
        "ℓ<sub>F</sub> do not depend on the stress"),
)


def _value(params, name):
    """The value in use of ``name``: the model term's (defaults filled in), else the wire's."""
    value = getattr(params.terms, name, None)
    return getattr(params, name) if value is None else value


def _fields(params, names):
    """{name: its number's HTML}; a term the file omits is marked as its default."""
    fields = {}
    for name in names:
        value = _value(params, name)
        unit = _UNITS.get(SPEC_BY_NAME[name].unit, SPEC_BY_NAME[name].unit)
        omitted = getattr(params, name) is None and value is not None
        fields[name] = "–" if value is None else \
            field(name, value, unit) + (" (default)" if omitted else "")
    return fields


def terms_html(params):
    """The HTML of every entry of :data:`TERM_PAGES` for the wire ``params``: the on terms'
    equations with their numbers, then the off terms named in one list."""
    on, off = [], []
    for entry in TERM_PAGES:
        fields = _fields(params, entry.numbers)
        if entry.active(params):
            on.append(f'<section class="term" data-term="{entry.key}" data-state="on">\n'
                      f"<h4>{html.escape(entry.title)} (on)</h4>\n"
                      f"{Template(entry.equations).substitute(fields)}\n</section>")
        else:
            off.append(f'<li class="term" data-term="{entry.key}" data-state="off">'
                       f"{html.escape(entry.title)}: off, "
                       f"{Template(entry.off).substitute(fields)}</li>")
    parts = on + ([f"<p>Terms this wire switches off:</p>\n<ul>\n" + "\n".join(off) + "\n</ul>"]
                  if off else [])
    return "\n".join(parts)


def inverse_html(params):
    """The inverse's method for the wire ``params``: the code's own words
    (:func:`~sma_fmu.runtime.sensing.inverse_method`), with the closed form for one stage."""
    two_stage = params.terms.two_stage
    method = html.escape(inverse_method(two_stage))
    if not two_stage:
        return ('<p class="eq">Λ = ln((M − ξ<sub>MF</sub>)/ξ<sub>MF</sub>) [1], &nbsp; '
                "T<sub>ref,K</sub> = 1 / (1/τ<sub>K</sub> − k<sub>B</sub> Λ / ΔH(f)) [K]</p>\n"
                f'<p class="inverse" data-method="closed form">Inverse: {method}.</p>')
    return ("<p>With its second stage (w<sub>2</sub> = "
            f"{field('w2', params.terms.w2, '')}) the branch ξ<sub>MF</sub>(T) of SmaActuator "
            "has no closed-form inverse:</p>\n"
            f'<p class="inverse" data-method="two-stage">Inverse: {method}.</p>')


def data_range_html(params):
    """The validity list's item on the range the wire's data covered (or that it has none)."""
    names = ("T_data_min", "T_data_max", "stress_data_min", "stress_data_max")
    if not params.data_range:
        return ("<li>Data range: this wire's file gives none (<code>T_data_min</code> … "
                "<code>stress_data_max</code>), so no warning for it.</li>")
    shown = _fields(params, names)
    loads = {name: "–" if getattr(params, name) is None else field(name, getattr(params, name), "kg")
             for name in ("load_data_min", "load_data_max")}
    return ("<li>Data range: the parameters were fitted to data from "
            f"{shown['T_data_min']} to {shown['T_data_max']} and from {shown['stress_data_min']} "
            f"to {shown['stress_data_max']} (loads {loads['load_data_min']} … "
            f"{loads['load_data_max']}). Outside it the model extrapolates the fit: it still "
            "computes, and the FMU logs one warning per instance, the first time.</li>")


def page_blocks(params):
    """{block: HTML} the models' pages take besides their numbers: ``terms``, ``inverse``,
    ``data_range``."""
    return {"terms": terms_html(params), "inverse": inverse_html(params),
            "data_range": data_range_html(params)}
