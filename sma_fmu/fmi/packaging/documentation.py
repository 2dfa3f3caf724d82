"""``documentation/index.html`` of an FMU, and the figure of its default experiment.

FMI 2.0 and 3.0 name ``documentation/index.html`` as the entry point of an FMU's
documentation. Ours speaks to the FMU's user: what the model is, its equations with units and
its validity range (the model's page, :mod:`.user_guide`, with the numbers of the wire the FMU
was built for), how to connect it in the closed loop (connections, step, Gauss-Seidel order),
every variable with its causality, type, unit, start value and description, the wire's
parameters (``resources/parameters.json``), its platforms
(:func:`~sma_fmu.fmi.packaging.platforms.platform_report`, else its ``binaries/`` folders), the
calling sequence of its FMI version, and a figure of its default experiment (``result.png``,
matplotlib) with the files of the reference result (:mod:`.reference_results`); for the
plant also ``hysteresis.png``, its resistance over its temperature in that experiment.
"""
import html
import json
import zipfile

from sma_fmu.files.png_output import png_bytes
from sma_fmu.fmi.packaging.user_guide import loop_section, model_section, wire_section

__all__ = ["FIGURE", "HYSTERESIS", "INDEX", "calling_sequence", "figure_png", "hysteresis_png",
           "index_html"]

INDEX = "documentation/index.html"
FIGURE = "documentation/result.png"
HYSTERESIS = "documentation/hysteresis.png"   # R over T, for a result with both

_CALLING_SEQUENCE = {
    "2": ("fmi2Instantiate(instanceName, fmi2CoSimulation, GUID, resourceURI, ...)",
          "fmi2SetupExperiment(startTime, [stopTime])",
          "fmi2EnterInitializationMode; set parameters and inputs (fmi2SetReal/Integer/Boolean/String)",
          "fmi2ExitInitializationMode: the parameters are checked here; the outputs are those at startTime",
          "repeat: set the inputs at t_k; fmi2DoStep(t_k, h) (t_k must be where the last step ended); "
          "get the outputs at t_k + h",
          "optionally fmi2GetFMUstate / fmi2SetFMUstate / fmi2SerializeFMUstate to go back",
          "fmi2Terminate; fmi2FreeInstance"),
    "3": ("fmi3InstantiateCoSimulation(instanceName, instantiationToken, resourcePath, visible, "
          "loggingOn, eventModeUsed, earlyReturnAllowed, ...)",
          "fmi3EnterInitializationMode(toleranceDefined, tolerance, startTime, stopTimeDefined, stopTime); "
          "set parameters and inputs (fmi3SetFloat64, fmi3SetInt32, fmi3SetInt64 for Enumerations, "
          "fmi3SetBoolean, fmi3SetString)",
          "fmi3ExitInitializationMode: the parameters are checked here; the outputs are those at "
          "startTime (with eventModeUsed the instance is then in Event Mode: fmi3EnterStepMode)",
          "repeat: set the inputs at t_k; fmi3DoStep(t_k, h, noSetFMUStatePriorToCurrentPoint, "
          "&eventHandlingNeeded, &terminateSimulation, &earlyReturn, &lastSuccessfulTime) (t_k must be "
          "where the last step ended); get the outputs at lastSuccessfulTime",
          "with eventModeUsed, when eventHandlingNeeded: fmi3EnterEventMode; "
          "fmi3UpdateDiscreteStates (it gives the next event time); fmi3EnterStepMode",
          "optionally fmi3GetFMUState / fmi3SetFMUState / fmi3SerializeFMUState to go back",
          "fmi3Terminate; fmi3FreeInstance"),
}


def calling_sequence(fmi_version):
    """The calling sequence (texts) for ``fmi_version`` ("2.0" or "3.0")."""
    return _CALLING_SEQUENCE[str(fmi_version)[0]]


def figure_png(result, inputs, units, title):
    """PNG bytes: the inputs (if any) and each output of the result over time, one axis each.

    ``result``/``inputs``: structured arrays with ``time`` first; ``units``: {name: unit}.
    """
    import matplotlib
    matplotlib.use("Agg")
    from matplotlib.figure import Figure

    outputs = list(result.dtype.names[1:])
    panels = ([("inputs", list(inputs.dtype.names[1:]), inputs)] if inputs is not None else []) + \
        [(name, [name], result) for name in outputs]
    figure = Figure(figsize=(8.0, 1.5 * len(panels) + 0.8), dpi=80, layout="constrained")
    axes = figure.subplots(len(panels), 1, sharex=True, squeeze=False)[:, 0]
    for axis, (label, names, data) in zip(axes, panels):
        for name in names:
            axis.plot(data["time"], data[name], label=f"{name} [{units.get(name) or '1'}]")
        axis.legend(loc="upper right", fontsize="small")
        axis.grid(True, alpha=0.3)
    axes[-1].set_xlabel("time [s]")
    figure.suptitle(title)
    return png_bytes(figure)


def hysteresis_png(result, units, title):
    """PNG bytes: R over T of ``result`` (a structured array), heating and cooling rows apart
    (its ``heating`` column, 1 or 0); None for a result without R and T."""
    names = result.dtype.names
    if "R" not in names or "T" not in names:
        return None
    import matplotlib
    matplotlib.use("Agg")
    from matplotlib.figure import Figure

    figure = Figure(figsize=(6.0, 4.5), dpi=80, layout="constrained")
    axis = figure.subplots()
    heating = result["heating"] > 0.5 if "heating" in names else result["T"] == result["T"]
    for rows, label, style in ((heating, "heating", "C3."), (~heating, "cooling", "C0.")):
        if rows.any():
            axis.plot(result["T"][rows], result["R"][rows], style, markersize=2, label=label)
    axis.set_xlabel(f"T [{units.get('T') or '1'}]")
    axis.set_ylabel(f"R [{units.get('R') or '1'}]")
    axis.legend(loc="upper right", fontsize="small")
    axis.grid(True, alpha=0.3)
    figure.suptitle(title)
    return png_bytes(figure)


def _table(head, rows):
    cells = "".join(f"<th>{html.escape(str(cell))}</th>" for cell in head)
    body = "".join("<tr>" + "".join(f"<td>{html.escape(str(cell))}</td>" for cell in row) + "</tr>"
                   for row in rows)
    return f"<table>\n<tr>{cells}</tr>\n{body}\n</table>"


def _unit(variable):
    if variable.unit:
        return variable.unit
    declared = variable.declaredType
    return declared.unit if declared is not None and getattr(declared, "unit", None) else ""


def _wire_document(archive):
    """resources/parameters.json of the archive (parsed), or None without one."""
    if "resources/parameters.json" not in archive.namelist():
        return None
    return json.loads(archive.read("resources/parameters.json"))


def _wire_rows(document):
    """(source, rows) of a parameters.json document, or (None, []) without one."""
    if document is None:
        return None, []
    rows = [(name, entry.get("value"), entry.get("unit", ""), entry.get("meaning", ""))
            for name, entry in document.get("parameters", {}).items()]
    return f"{document.get('name', '')} ({document.get('description', '')})", rows


def _wire_parameters(document):
    """The :class:`~sma_fmu.runtime.parameters.WireParameters` of a parameters.json document
    (the FMU's wire), or None without one."""
    from sma_fmu.runtime.parameters import WireParameters

    if document is None:
        return None
    return WireParameters.from_values({name: entry["value"]
                                       for name, entry in document["parameters"].items()},
                                      source="resources/parameters.json")


def _platform_rows(fmu_path, archive):
    from sma_fmu.fmi.packaging.platforms import platform_report

    report = platform_report(fmu_path)
    if report and report[0][0] != "n/a":
        return [(name, status, detail) for status, name, detail in report]
    folders = {}
    for name in archive.namelist():
        parts = name.split("/")
        if parts[0] == "binaries" and len(parts) == 3 and parts[2]:
            folders.setdefault(parts[1], []).append(parts[2])
    return [(folder, "", ", ".join(sorted(files))) for folder, files in sorted(folders.items())]


def _model_part(name, description, params):
    """The model's page (what it is, equations, validity range), else its description."""
    section = model_section(name, params) if params is not None else ""
    if section:
        return section
    return f"<h2>What the model is</h2>\n<p>{html.escape(description.description or '')}</p>"


def _event_note(description):
    """FMI 3.0: what event mode does in this FMU ("" for FMI 2.0 or without event mode)."""
    cs = description.coSimulation
    if not description.fmiVersion.startswith("3") or cs is None or not getattr(cs, "hasEventMode", False):
        return ""
    if getattr(cs, "mightReturnEarlyFromDoStep", False):
        return ("<p>Event mode: this FMU has events of its own, its discontinuities (the PWM "
                "driver's switching edges; the scenario's load switching times and reference "
                "steps). With eventModeUsed a step that ends at one sets eventHandlingNeeded, and "
                "with earlyReturnAllowed a step stops at the first one inside it "
                "(earlyReturn, lastSuccessfulTime). Without them it steps as the FMI 2.0 FMU does.</p>")
    return ("<p>Event mode: this FMU accepts eventModeUsed but has no events of its own; its "
            "steps are the same with or without it.</p>")


def index_html(fmu_path, description, experiment, files):
    """The text of documentation/index.html of the FMU ``fmu_path`` (FMI 2.0 or 3.0).

    ``description``: fmpy's model description; ``experiment``: its
    :class:`~.reference_results.Experiment`; ``files``: {role: archive path} of the reference
    files ("manifest", "result", and "stimuli" when it has inputs).
    """
    name = description.modelName
    version = description.fmiVersion
    fmi = "fmi3" if version.startswith("3") else "fmi2"
    variables = [(v.name, v.causality, v.variability, v.type, _unit(v) or "–",
                  "" if v.start is None else v.start, v.description or "")
                 for v in description.modelVariables]
    with zipfile.ZipFile(fmu_path) as archive:
        document = _wire_document(archive)
        platforms = _platform_rows(fmu_path, archive)
    source, wire = _wire_rows(document)
    e = html.escape
    stimuli = files.get("stimuli")
    run = ("import numpy as np\nfrom fmpy import simulate_fmu\n"
           + (f"inputs = np.genfromtxt('{stimuli}', delimiter=',', names=True)  # unpacked\n"
              if stimuli else "inputs = None\n")
           + f"result = simulate_fmu('{name}.fmu', start_time={experiment.start!r}, "
             f"stop_time={experiment.stop!r}, output_interval={experiment.step!r}, input=inputs)\n")
    token = "instantiation token" if fmi == "fmi3" else "GUID"
    parts = [
        "<!DOCTYPE html>", "<html lang=\"en\">", "<head>", "<meta charset=\"utf-8\">",
        f"<title>{e(name)}</title>",
        "<style>body{font-family:sans-serif;max-width:60em;margin:auto}table{border-collapse:"
        "collapse}td,th{border:1px solid #bbb;padding:2px 6px;text-align:left;vertical-align:top}"
        "pre{background:#f4f4f4;padding:6px;white-space:pre-wrap}.eq{margin-left:2em;"
        "font-family:serif;font-size:110%}</style>",
        "</head>", "<body>",
        f"<h1>{e(name)}</h1>",
        f"<p>{e(description.description or '')}</p>",
        f"<p>FMI {e(version)} co-simulation, generated by {e(description.generationTool or '')}"
        + (f" ({e(description.generationDateAndTime)})" if description.generationDateAndTime else "")
        + f", {token} {e(description.guid or '')}.</p>",
        wire_section(document),
        _model_part(name, description, _wire_parameters(document)),
        loop_section(name, experiment.step),
        "<h2>Variables</h2>",
        _table(("name", "causality", "variability", "type", "unit", "start", "description"), variables),
        "<h2>The wire's parameters</h2>",
        (f"<p>Built from the parameter file {e(source)} (resources/parameters.json); the FMU's "
         "parameters above start at these values.</p>" + _table(("name", "value", "unit", "meaning"), wire))
        if wire else "<p>This FMU carries no parameter file: its parameters are in the table above.</p>",
        "<h2>Platforms</h2>", _table(("platform", "status", "binary and notes"), platforms),
        "<h2>Calling sequence</h2>",
        "<ol>" + "".join(f"<li><code>{e(step)}</code></li>" for step in calling_sequence(version)) + "</ol>",
        _event_note(description),
        f"<p>Invalid inputs make {fmi}DoStep return {fmi}Discard with a log message and change "
        "nothing; the instance goes on with valid ones. Log categories: logStatusWarning, "
        "logStatusDiscard, logStatusError (see the model description).</p>",
        "<h2>Default experiment and reference result</h2>",
        f"<p>startTime = {experiment.start!r} s, stopTime = {experiment.stop!r} s, communication "
        f"step {experiment.step!r} s. "
        + (f"Inputs: piecewise linear, from <code>{e(stimuli)}</code> (linear in between). "
           if stimuli else "No inputs. ")
        + f"The result, every output at the rows of <code>{e(files['result'])}</code>, is listed in "
          f"<code>{e(files['manifest'])}</code> (FMI-LS-REF layout); <code>sma-fmu check</code> "
          "runs the experiment again and compares. With fmpy:</p>",
        f"<pre>{e(run)}</pre>",
        f"<img src=\"result.png\" alt=\"{e(name)}: the default experiment\">",
        (f"<p>Its resistance over its temperature in that experiment: the heating and the "
         f"cooling branch of the hysteresis.</p>\n<img src=\"{e(files['hysteresis'].split('/')[-1])}\" "
         f"alt=\"{e(name)}: R over T\">" if files.get("hysteresis") else ""),
        "</body>", "</html>", ""]
    return "\n".join(parts)
