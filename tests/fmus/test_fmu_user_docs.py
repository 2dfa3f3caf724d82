"""documentation/index.html speaks to the FMU's user, in every family and version
(sma_fmu/fmi/packaging/user_guide.py, fmi/models/<Model>/page.html, documentation.py), and the FMI 3.0 FMUs
carry their own fmi-ls-ref reference result, which ``sma-fmu check`` verifies (extras.py,
fmi3_build.py, reference_results.py)."""
import html
import re
import xml.etree.ElementTree as ET
import zipfile
from html.parser import HTMLParser

import pytest

from sma_fmu.cli import main
from sma_fmu.fmi.packaging.reference_results import LS_REF_FOLDER, MANIFEST, reference_check
from sma_fmu.runtime.pwm import MAX_FREQUENCY_HZ, MIN_FREQUENCY_HZ
from sma_fmu.runtime.reachable_band import reachable_band
from sma_fmu.systems.check import check_file
from sma_fmu.fmi.loop.wiring import COMPONENT_MODELS, STEP_ORDER, loop_connections
from sma_fmu.wire.parameter_file import load_parameters

pytestmark = pytest.mark.needs("gcc")

NAMES = ["SmaActuator", "SmaFeedforward", "SmaPiController", "SmaPwmDriver", "SmaScenarioSignals"]
FAMILIES = ["pythonfmu-fmi2", "c-fmi2", "c-fmi3"]
LS = "{http://fmi-standard.org/fmi-ls-manifest}"
VOID = {"meta", "img", "br", "hr", "input", "link", "col", "wbr"}

# per model: units its equations section must state, and the validity numbers it must quote
UNITS = {"SmaActuator": ("[W]", "[°C]", "[Ω]", "[m]", "[J]", "[Pa]", "K/W"),
         "SmaFeedforward": ("[W]", "[K]", "[°C]", "[J]", "[s]", "K/W"),
         "SmaPiController": ("[Ω]", "[W]", "[Ω·s]", "[W/Ω]", "[W/(Ω·s)]"),
         "SmaPwmDriver": ("[W]", "[Hz]", "[s]", "[1]"),
         "SmaScenarioSignals": ("[Ω]", "[kg]", "[s]")}
LIMITS = {"SmaActuator": ("T_max", "stress_max", "load_max", "P_T_max", "R_hot_0", "R_cold_0"),
          "SmaFeedforward": ("T_max", "stress_max", "load_max", "P_T_max", "R_hot_max", "R_cold_max"),
          "SmaPiController": ("T_max", "P_T_max", "R_hot_0", "R_cold_0"),
          "SmaPwmDriver": ("T_max", "P_T_max", "f_min", "f_max"),
          "SmaScenarioSignals": ("load_max", "stress_max", "R_hot_0", "R_cold_max")}


@pytest.fixture(params=FAMILIES)
def family(request):
    fixture = {"pythonfmu-fmi2": "fmus", "c-fmi2": "native_fmus", "c-fmi3": "fmi3_fmus"}[request.param]
    return request.param, request.getfixturevalue(fixture)


def _read(path, name):
    with zipfile.ZipFile(path) as archive:
        return archive.read(name)


class _TagChecker(HTMLParser):
    """Records every tag left open or closed out of order."""

    def __init__(self):
        super().__init__(convert_charrefs=True)
        self.open, self.problems, self.sources = [], [], []

    def handle_starttag(self, tag, attrs):
        attributes = dict(attrs)
        self.sources += [value for key, value in attrs if key in ("src", "href")]
        if tag == "img":
            self.sources.append("img:" + attributes.get("src", ""))
        if tag not in VOID:
            self.open.append(tag)

    def handle_endtag(self, tag):
        if not self.open or self.open[-1] != tag:
            self.problems.append(f"</{tag}> closes {self.open[-1:]}")
        else:
            self.open.pop()


def _section(text, heading):
    """The HTML from <h2>heading</h2> to the next <h2>."""
    start = text.index(f"<h2>{heading}</h2>")
    end = text.find("<h2>", start + 1)
    return text[start:end if end > 0 else len(text)]


def _expected_limits(params):
    """The validity numbers from the runtime, computed here."""
    no_load, at_limit = reachable_band(0.0, params), reachable_band(params.load_max, params)
    return {"T_max": params.T_max, "stress_max": params.stress_max, "load_max": params.load_max,
            "P_T_max": (params.T_max - params.T_room) / params.K_th,
            "R_hot_0": no_load.hot, "R_cold_0": no_load.cold,
            "R_hot_max": at_limit.hot, "R_cold_max": at_limit.cold,
            "f_min": MIN_FREQUENCY_HZ, "f_max": MAX_FREQUENCY_HZ}


def test_each_index_html_is_well_formed_and_offline(family):
    label, fmus = family
    for model in NAMES:
        text = _read(fmus[model], "documentation/index.html").decode("utf-8")
        checker = _TagChecker()
        checker.feed(text)
        checker.close()
        assert checker.problems == [] and checker.open == [], (label, model, checker.problems, checker.open)
        assert "<script" not in text and "<link" not in text, (label, model)
        assert not [s for s in checker.sources if "//" in s], (label, model, checker.sources)
        figures = [s[4:] for s in checker.sources if s.startswith("img:")]
        assert figures[0] == "result.png", (label, model)
        # the plant also shows its hysteresis, R over T, from the same reference result
        assert ("hysteresis.png" in figures) == (model == "SmaActuator"), (label, model, figures)
        for figure in figures:   # the figure it shows is in the archive, a PNG
            assert _read(fmus[model], f"documentation/{figure}")[:8] == b"\x89PNG\r\n\x1a\n", figure


def test_each_index_html_gives_equations_units_validity_and_loop(family, params):
    label, fmus = family
    expected = _expected_limits(params)
    for model in NAMES:
        text = _read(fmus[model], "documentation/index.html").decode("utf-8")
        what = _section(text, "What the model is")
        assert "adapter" not in what and "renamed" not in what and "sma_fmu.runtime" not in what
        equations = html.unescape(_section(text, "Equations"))
        for unit in UNITS[model]:
            assert unit in equations, (label, model, unit)
        validity = _section(text, "Validity range")
        quoted = {name: (float(value), shown) for name, value, shown in re.findall(
            r'<span class="limit" data-name="(\w+)" data-value="([^"]+)">([^<]*)</span>', validity)}
        for name in LIMITS[model]:
            assert name in quoted, (label, model, name)
            assert quoted[name][0] == pytest.approx(expected[name], rel=1e-15, abs=0.0), (model, name)
            assert quoted[name][1].startswith(f"{expected[name]:.4g} "), (model, name, quoted[name])
        loop = _section(text, "Connecting the FMU in a loop")
        role = next(r for r, m in COMPONENT_MODELS.items() if m == model)
        touching = [c for c in loop_connections(True, True) if role in (c.source, c.target)]
        assert touching, model
        for c in touching:
            assert (f"<td><code>{COMPONENT_MODELS[c.source]}.{c.output}</code></td>"
                    f"<td><code>{COMPONENT_MODELS[c.target]}.{c.input}</code></td>") in loop, (model, c)
        order = re.sub(r"</?b>", "", loop)
        assert " → ".join(COMPONENT_MODELS[r] for r in STEP_ORDER) in order, model
        assert "0.001 s" in loop


def test_the_validity_numbers_follow_the_wire_the_fmu_was_built_for(params):
    """Not text fixed in a page: another wire's parameters.json gives other numbers."""
    from sma_fmu.fmi.packaging.user_guide import model_section

    hotter = params.replace(T_max=250.0, stress_max=200.0)
    text = model_section("SmaActuator", hotter)
    assert 'data-name="T_max" data-value="250.0">250 °C</span>' in text
    assert f'data-name="load_max" data-value="{hotter.load_max!r}"' in text
    assert hotter.load_max < params.load_max
    assert model_section("NoSuchModel", params) == ""


def test_the_calling_sequence_is_the_fmus_version(family):
    label, fmus = family
    own, other = ("fmi3", "fmi2") if label.endswith("fmi3") else ("fmi2", "fmi3")
    for model in NAMES:
        sequence = _section(_read(fmus[model], "documentation/index.html").decode("utf-8"),
                            "Calling sequence")
        assert f"{own}DoStep" in sequence and f"{other}DoStep" not in sequence, (label, model)
        # FMI 3.0's event mode: the models with events of their own say so, the others that
        # they have none; FMI 2.0 has no event mode in co-simulation
        if own == "fmi3":
            has_events = model in ("SmaPwmDriver", "SmaScenarioSignals")
            assert ("has events of its own" in sequence) == has_events, model
            assert ("has no events of its own" in sequence) == (not has_events), model
        else:
            assert "Event mode" not in sequence, (label, model)


def _csv_columns(data):
    """{column name: its cells as written} of a reference CSV (bytes)."""
    rows = [line.split(",") for line in data.decode("utf-8").splitlines()]
    return {name.strip('"'): [row[i] for row in rows[1:]] for i, name in enumerate(rows[0])}


def test_fmi3_fmus_carry_their_own_reference_equal_to_the_fmi2_twins(fmi3_fmus, fmus):
    """Run by the FMI 3.0 FMU at build time; the pythonfmu FMI 2.0 twin's, byte for byte, in
    every file and column they share (FMI 3.0's plant adds one output: reversal_count)."""
    for model in NAMES:
        names = set(zipfile.ZipFile(fmi3_fmus[model]).namelist())
        files = [MANIFEST, f"{LS_REF_FOLDER}/{model}_out.csv"] + \
            ([f"{LS_REF_FOLDER}/{model}_in.csv"] if model != "SmaScenarioSignals" else [])
        assert set(files) | {"documentation/index.html", "documentation/result.png"} <= names, model
        for name in files:
            if name.endswith("_out.csv"):
                three, two = (_csv_columns(_read(f[model], name)) for f in (fmi3_fmus, fmus))
                extra = {"reversal_count"} if model == "SmaActuator" else set()
                assert set(three) == set(two) | extra, (model, sorted(three), sorted(two))
                assert all(three[column] == two[column] for column in two), (model, name)
            else:
                assert _read(fmi3_fmus[model], name) == _read(fmus[model], name), (model, name)
        root = ET.fromstring(_read(fmi3_fmus[model], MANIFEST))   # FMI 3.0's layered-standard manifest
        assert root.get(f"{LS}fmi-ls-name") == LS_REF_FOLDER.split("/")[1], model
        assert root.get(f"{LS}fmi-ls-version") and root.get(f"{LS}fmi-ls-description"), model
        status, detail = reference_check(fmi3_fmus[model])
        assert status == "ok" and "10000 steps of 0.001 s" in detail, (model, detail)


def test_a_corrupted_fmi3_reference_fails_check(fmi3_fmus, tmp_path, capsys):
    source = fmi3_fmus["SmaActuator"]
    path = tmp_path / "SmaActuator.fmu"
    entry = f"{LS_REF_FOLDER}/SmaActuator_out.csv"
    with zipfile.ZipFile(source) as archive, zipfile.ZipFile(path, "w") as out:
        for item in archive.infolist():
            data = archive.read(item.filename)
            if item.filename == entry:
                lines = data.decode().splitlines()
                header = [name.strip('"') for name in lines[0].split(",")]
                row = lines[500].split(",")
                column = header.index("T")
                row[column] = repr(float(row[column]) + 1e-6)   # 1 uK off, far above 1e-9 relative
                lines[500] = ",".join(row)
                data = ("\n".join(lines) + "\n").encode()
            out.writestr(item, data)
    status, detail = reference_check(path)
    assert status == "FAIL" and detail.startswith("T at t = "), detail
    lines = {result.check: result for result in check_file(path)}
    assert lines["default experiment"].status == "FAIL"
    assert main(["check", str(path)]) != 0
    assert "FAIL" in capsys.readouterr().out
    assert reference_check(source)[0] == "ok"


def test_c_family_fmi2_documentation_is_added_after_the_twins_reference(native_fmus, fmus):
    """The native FMI 2.0 FMUs keep their twin's extra/ and gain documentation/ at the end."""
    for model in NAMES:
        with zipfile.ZipFile(native_fmus[model]) as archive:
            names = archive.namelist()
        documentation = ["documentation/result.png"] + \
            (["documentation/hysteresis.png"] if model == "SmaActuator" else []) + ["documentation/index.html"]
        assert names[-len(documentation):] == documentation, model
        assert not [n for n in names[:-len(documentation)] if n.startswith("documentation/")], model
        for name in [n for n in names if n.startswith("extra/")]:
            assert _read(native_fmus[model], name) == _read(fmus[model], name), (model, name)
        text = _read(native_fmus[model], "documentation/index.html").decode("utf-8")
        assert "native C" in text and "FMI 2.0 co-simulation" in text, model
