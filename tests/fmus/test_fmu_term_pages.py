"""The page of an FMU (documentation/index.html) shows the model the FMU runs: built from the
Flexinol fit, in every family and version, the plant's and the compensator's pages show
every optional term of that wire as on (the second stage, separate widths, thermal expansion
with T_alpha, the stress law), each with the wire file's own numbers, the compensator's
inverse by the method the runtime uses for two stages, and the range the data covered;
built from the reference wire, they name every term as off, the closed-form inverse and no
data range. The numbers are read off the HTML, not off the code that wrote it."""
import tomllib
import zipfile
from html.parser import HTMLParser

import pytest

from real_isobaric import real_folder
from sma_fmu.cli import main
from sma_fmu.runtime.sensing import inverse_method

pytestmark = pytest.mark.needs("gcc")

MODELS = ["SmaActuator", "SmaFeedforward"]
TERMS = ("widths", "second_stage", "thermal_expansion", "stress_law")
# what each term quotes when it is on (docs/model.md, 4a), and the defaults of the terms a
# file may omit (the same table): T_alpha 20 degC, span_ratio_sat 1
ON_NUMBERS = {"widths": ("nu_h", "nu_c"),
              "second_stage": ("w2", "a2_h", "b2_h", "a2_c", "b2_c", "nu2_h", "nu2_c"),
              "thermal_expansion": ("alpha_P", "alpha_MF", "T_alpha"),
              "stress_law": ("span_ratio_0", "span_ratio_sat", "span_stress")}
OMITTED = {"T_alpha": 20.0, "span_ratio_sat": 1.0}
DATA_RANGE = ("T_data_min", "T_data_max", "stress_data_min", "stress_data_max")


class _Page(HTMLParser):
    """The page's numbers ({data-name: {float}}), terms ({data-term: data-state}) and the
    inverse's paragraph (data-method, text)."""

    def __init__(self, text):
        super().__init__(convert_charrefs=True)
        self.numbers, self.terms, self.inverse, self._inverse_open = {}, {}, None, False
        self.feed(text)

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if a.get("class") == "limit":
            self.numbers.setdefault(a["data-name"], set()).add(float(a["data-value"]))
        if a.get("class") == "term":
            self.terms[a["data-term"]] = a["data-state"]
        if tag == "p" and a.get("class") == "inverse":
            self.inverse, self._inverse_open = [a["data-method"], ""], True

    def handle_endtag(self, tag):
        if tag == "p":
            self._inverse_open = False

    def handle_data(self, data):
        if self._inverse_open:
            self.inverse[1] += data


def _page(path):
    with zipfile.ZipFile(path) as archive:
        return _Page(archive.read("documentation/index.html").decode("utf-8"))


@pytest.fixture(scope="module")
def flexinol_fmus(tmp_path_factory):
    """The Flexinol fit (every option its default) and the plant's and compensator's FMUs of
    every family and version built from it: (the wire file's values, {kind: {model: path}})."""
    folder = real_folder("flexinol-niti")
    root = tmp_path_factory.mktemp("flexinol_pages")
    files = [str(folder / f"isobaric_{s}MPa.txt") for s in (50, 100, 172, 200)]
    assert main(["fit", "isobaric", *files, "--out", str(root / "fit")]) == 0
    wire = root / "fit" / "identified.toml"
    from sma_fmu.fmi.packaging.build import build_fmus
    from sma_fmu.fmi.packaging.c_family_build import build_native_fmus
    from sma_fmu.fmi.packaging.fmi3_build import build_fmi3_fmus
    built = {"py": build_fmus(root / "py", wire, names=MODELS),
             "nat": build_native_fmus(root / "nat", wire, names=MODELS),
             "fmi3": build_fmi3_fmus(root / "fmi3", wire, names=MODELS)}
    document = tomllib.loads(wire.read_text(encoding="utf-8"))
    values = {key: entry["value"] for name, section in document.items() if name != "wire"
              for key, entry in section.items()}
    return values, built


@pytest.mark.parametrize("kind", ["py", "nat", "fmi3"])
@pytest.mark.parametrize("model", MODELS)
def test_the_flexinol_pages_show_every_term_with_the_files_numbers(flexinol_fmus, kind, model):
    values, built = flexinol_fmus
    page = _page(built[kind][model])
    assert page.terms == {term: "on" for term in TERMS}
    for term, names in ON_NUMBERS.items():
        for name in names:
            expected = values[name] if name in values else OMITTED[name]
            assert page.numbers[name] == {expected}, (term, name)
    assert values["w2"] > 0.1 and values["alpha_P"] != 0.0 and values["span_ratio_0"] != 1.0
    for name in DATA_RANGE:            # the range the data covered, as the file states it
        assert page.numbers[name] == {values[name]}, name
    assert (values["T_data_min"], values["stress_data_max"]) < (31.0, 201.0)
    if model == "SmaFeedforward":
        method, text = page.inverse
        assert method == "two-stage" and text.strip() == f"Inverse: {inverse_method(True)}."
        assert inverse_method(True) != inverse_method(False)
    else:
        assert page.inverse is None   # the plant does not invert


@pytest.fixture(params=["fmus", "native_fmus", "fmi3_fmus"])
def reference(request):
    return request.getfixturevalue(request.param)


@pytest.mark.parametrize("model", MODELS)
def test_the_reference_pages_name_every_term_as_off(reference, params, model):
    page = _page(reference[model])
    assert page.terms == {term: "off" for term in TERMS}
    assert page.numbers["w2"] == {0.0} and page.numbers["nu"] == {params.nu}
    assert page.numbers["alpha_P"] == {0.0} and page.numbers["span_ratio_0"] == {1.0}
    assert not set(DATA_RANGE) & set(page.numbers)
    if model == "SmaFeedforward":
        method, text = page.inverse
        assert method == "closed form" and text.strip() == f"Inverse: {inverse_method(False)}."
