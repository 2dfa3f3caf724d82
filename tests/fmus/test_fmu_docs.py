"""docs/fmus.md lists every variable of every FMU exactly as the built FMUs declare it."""
from pathlib import Path

from sma_fmu.fmi.packaging.fmu_names import FMU_SCRIPTS
from sma_fmu.fmi.packaging.variable_table import markdown_table, render_document

DOC = Path(__file__).parents[2] / "docs" / "fmus.md"


def test_variable_tables_in_docs_match_the_built_fmus(fmus):
    assert set(fmus) == set(FMU_SCRIPTS)
    text = DOC.read_text(encoding="utf-8")
    assert render_document(text, fmus) == text, (
        "docs/fmus.md differs from the FMUs: run python -m sma_fmu.fmi.packaging.variable_table docs/fmus.md")


def test_the_table_has_a_row_per_variable_with_unit_and_start(fmus):
    table = markdown_table(fmus["SmaActuator"]).splitlines()
    rows = {line.split(" | ")[0].strip("| `"): line.split(" | ") for line in table[2:]}
    assert rows["P_in"][1:5] == ["input", "continuous", "Real", "W"] and float(rows["P_in"][5]) == 0.0
    assert rows["hysteresis_mode"][3:6] == ["Integer", "–", "1"]
    assert rows["R"][1:6] == ["output", "continuous", "Real", "ohm", "(calculated)"]
    assert rows["T_max"][1:5] == ["parameter", "fixed", "Real", "degC"] and float(rows["T_max"][5]) == 300.0
