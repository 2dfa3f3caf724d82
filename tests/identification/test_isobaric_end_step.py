"""A strain step at a file's start or end that no temperature explains (isobaric/end_step.py):
the rows beyond it are left out with a note naming them, and the file then reads as the
same file without those rows; a file without a step, or with one inside it, is untouched."""
import numpy as np
import pytest

from sma_fmu.identification.isobaric.files import read_isobaric
from sma_fmu.identification.isobaric.synthetic import IsobaricProgramme, isobaric_table

LOAD = 0.3
ROWS = 1200
HEADER = 1                       # the column row is line 1, the first data row line 2


@pytest.fixture(scope="module")
def columns(parameter_set):
    programme = IsobaricProgramme(t_low=20.0, t_high=130.0, rate=10.0, cycles=2, dwell=60.0,
                                  points=ROWS, noise_K=0.3, noise_strain=2e-5, seed=3)
    table, _ = isobaric_table(parameter_set.params, LOAD, programme, strain_unit="fraction")
    return np.asarray(table["temperature_C"]), np.asarray(table["strain"])


def _write(path, temperature, strain):
    lines = ["temperature_C,strain"] + [f"{t:.3f},{e:.7f}" for t, e in zip(temperature, strain)]
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


def _step_notes(data):
    return [note for note in data.notes if "the strain steps by" in note]


@pytest.mark.parametrize("where, rows", [("last", slice(ROWS - 30, ROWS)),
                                         ("first", slice(0, 25))])
def test_rows_beyond_a_step_at_an_end_are_left_out(tmp_path, columns, where, rows):
    temperature, strain = columns
    stepped = strain.copy()
    size = 10.0 * np.abs(np.diff(strain)).max()   # twice the factor of 5 over any other step
    stepped[rows] += size
    data = read_isobaric(_write(tmp_path / "stepped.csv", temperature, stepped), load=LOAD)
    keep = np.ones(ROWS, bool)
    keep[rows] = False
    plain = read_isobaric(_write(tmp_path / "plain.csv", temperature[keep], strain[keep]),
                          load=LOAD)
    np.testing.assert_array_equal(data.strain, plain.strain)
    np.testing.assert_array_equal(data.temperature, plain.temperature)
    first, last = rows.start + HEADER + 1, rows.stop + HEADER
    (note,) = _step_notes(data)
    head = (f"lines {first}-{last} (the {where} {rows.stop - rows.start} rows) left out: "
            f"the strain steps by ")
    assert note.startswith(head)
    written = float(note[len(head):].split(" %")[0]) / 100.0      # the step as the note says it
    sign = 1.0 if where == "last" else -1.0
    assert abs(written - sign * size) <= np.abs(np.diff(strain)).max()


def test_a_file_without_a_step_or_with_one_inside_is_untouched(tmp_path, columns):
    temperature, strain = columns
    data = read_isobaric(_write(tmp_path / "plain.csv", temperature, strain), load=LOAD)
    assert data.strain.size == ROWS and not _step_notes(data)
    inside = strain.copy()
    inside[ROWS // 2:] += 10.0 * np.abs(np.diff(strain)).max()   # half the file beyond it
    data = read_isobaric(_write(tmp_path / "inside.csv", temperature, inside), load=LOAD)
    assert data.strain.size == ROWS and not _step_notes(data)
