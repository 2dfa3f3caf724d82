"""What ``documentation/index.html`` tells an FMU's user about its model, in either FMI version.

The text of each model (what it is, its equations with units, its validity range) is an HTML
fragment, the page in the model's folder (``fmi/models/<Model>/page.html``). Its ``${name}``
fields are the numbers of the wire the FMU was built for (:func:`limits`, from its
``resources/parameters.json``), each written as
``<span class="limit" data-name="name" data-value="repr">value unit</span>`` so a reader sees
the value with its unit and a test can read the exact number back. Three fields are blocks
of HTML (:func:`~.term_pages.page_blocks`): ``${terms}``, the optional model terms, each
with its equations and numbers when the wire switches it on, named as off when not;
``${inverse}``, how the compensator inverts this wire's branch; ``${data_range}``, the range
the wire's data covered.

:func:`wire_section` names the wire the FMU was built from: its parameter file and the
digest of its values, which the model description states too (``wire_digest``).

:func:`loop_section` says how to connect the FMU in the closed loop: the connections of
:func:`sma_fmu.fmi.loop.wiring.loop_connections` that touch the model, and its place in
the Gauss-Seidel order :data:`~sma_fmu.fmi.loop.wiring.STEP_ORDER`.
"""
import html
from string import Template

from sma_fmu.fmi.models import REGISTRY, declaration
from sma_fmu.fmi.packaging.term_pages import field, page_blocks
from sma_fmu.fmi.loop.wiring import COMPONENT_MODELS, STEP_ORDER, loop_connections

__all__ = ["limits", "page_template", "model_section", "wire_section", "loop_section"]


def limits(params):
    """{field: (value, unit)} of the wire ``params`` (:class:`~sma_fmu.runtime.parameters.WireParameters`):
    the validity range and the constants the pages quote."""
    from sma_fmu.runtime.pwm import MAX_FREQUENCY_HZ, MIN_FREQUENCY_HZ
    from sma_fmu.runtime.reachable_band import reachable_band
    from sma_fmu.runtime.signals import MAX_REFERENCE_OHM

    no_load, at_limit = reachable_band(0.0, params), reachable_band(params.load_max, params)
    return {
        "T_max": (params.T_max, "°C"), "T_room": (params.T_room, "°C"),
        "stress_max": (params.stress_max, "MPa"), "load_max": (params.load_max, "kg"),
        "diameter": (params.diameter * 1e3, "mm"),
        "K_th": (params.K_th, "K/W"), "tau_th": (params.tau_th, "s"),
        # the held power whose steady state is T_max: T_room + K_th P = T_max
        "P_T_max": ((params.T_max - params.T_room) / params.K_th, "W"),
        "R_hot_0": (no_load.hot, "Ω"), "R_cold_0": (no_load.cold, "Ω"),
        "R_hot_max": (at_limit.hot, "Ω"), "R_cold_max": (at_limit.cold, "Ω"),
        "Kp": (params.Kp, "W/Ω"), "Ki": (params.Ki, "W/(Ω·s)"),
        "f_min": (MIN_FREQUENCY_HZ, "Hz"), "f_max": (MAX_FREQUENCY_HZ, "Hz"),
        "R_ref_max": (MAX_REFERENCE_OHM, "Ω"),
    }


def page_template(model_name):
    """The page of ``model_name`` (a :class:`string.Template`); None for a model not registered."""
    if model_name not in REGISTRY:
        return None
    return Template(declaration(model_name).page.read_text(encoding="utf-8"))


def model_section(model_name, params):
    """The HTML of what the model is, its equations and validity range, with the numbers of
    ``params``; "" for a model without a page."""
    template = page_template(model_name)
    if template is None:
        return ""
    fields = {name: field(name, value, unit) for name, (value, unit) in limits(params).items()}
    fields.update(page_blocks(params))   # the model terms, the inverse, the data range
    return template.substitute(fields)   # a field the page names and limits() lacks: KeyError


def wire_section(document):
    """The HTML naming the wire of a parameters.json ``document`` (the FMU's): its name, its
    parameter file and its digest; "" without one."""
    if document is None:
        return ""
    from sma_fmu.runtime.parameters import WireParameters
    from sma_fmu.runtime.wire_identity import wire_digest

    e = html.escape
    params = WireParameters.from_values({name: entry["value"] for name, entry
                                         in document["parameters"].items()})
    return (f'<p class="wire">Wire: {e(str(document.get("name", "")))}, from the parameter file '
            f'<code class="wire-file">{e(str(document.get("source", "")))}</code>; digest '
            f'<code class="wire-digest">{e(wire_digest(params))}</code> (SHA-256 of its values, '
            "as the String constant <code>wire_digest</code> states it). A master sets a "
            "scenario's whole wire in the FMU: an optional parameter at NaN is not given.</p>")


def _connection_rows(model_name):
    """(from, to, note) of the loop connections that touch ``model_name``."""
    role = next(name for name, model in COMPONENT_MODELS.items() if model == model_name)
    full = loop_connections(feedforward=True, pwm=True)
    direct = [c for c in loop_connections(feedforward=True, pwm=False) if c not in full]
    limited = [c for c in loop_connections(feedforward=True, pwm=True, limited=True) if c not in full]
    rows = []
    for connection, note in ([(c, "") for c in full] + [(c, "without the PWM driver") for c in direct]
                             + [(c, "with a current or voltage limit") for c in limited]):
        if role in (connection.source, connection.target):
            rows.append((f"{COMPONENT_MODELS[connection.source]}.{connection.output}",
                         f"{COMPONENT_MODELS[connection.target]}.{connection.input}", note))
    return role, rows


def loop_section(model_name, step):
    """The HTML of how ``model_name`` sits in the closed loop, sampled every ``step`` [s]."""
    if model_name not in COMPONENT_MODELS.values():
        return ""
    role, rows = _connection_rows(model_name)
    e = html.escape
    order = " → ".join(f"<b>{e(COMPONENT_MODELS[r])}</b>" if r == role else e(COMPONENT_MODELS[r])
                       for r in STEP_ORDER)
    cells = "".join(f"<tr><td><code>{e(a)}</code></td><td><code>{e(b)}</code></td><td>{e(n)}</td></tr>"
                    for a, b, n in rows)
    return "\n".join([
        "<h2>Connecting the FMU in a loop</h2>",
        "<p>The closed loop of sma-fmu's scenarios: SmaScenarioSignals gives R_ref and the load, "
        "SmaFeedforward the feedforward power, SmaPiController the heating power, SmaPwmDriver "
        "(optional) switches it, SmaActuator is the wire. This FMU's connections (output → input):</p>",
        f"<table class=\"loop\">\n<tr><th>output</th><th>input</th><th>note</th></tr>\n{cells}\n</table>",
        f"<p>Sample every block at the same communication step h, {e(repr(step))} s in the default "
        "experiment and the scenarios (1 ms). Within step k (t<sub>k</sub> → t<sub>k</sub> + h) "
        f"step the FMUs in this Gauss-Seidel order, each after setting its inputs from the outputs "
        f"already computed: {order}. So every block of step k sees R<sub>k</sub>, "
        "R_ref(t<sub>k</sub>), f(t<sub>k</sub>) and the powers just computed for step k, as the "
        "library loop does; an input left unconnected keeps its start value.</p>",
    ])
