"""The native FMUs on Windows: the closed loop stepped by their win64 binaries under wine64.

The plain C loop host (sma_fmu/fmi/hosts/loop_host.c) is built twice from one source: with
gcc, loading binaries/linux64/*.so, and with mingw-w64, loading binaries/win64/*.dll under
Debian's wine64. Both step the five native FMUs (signals, compensator, PI, PWM driver,
plant) as a sequential (Gauss-Seidel) loop. The linux64 run equals the library loop; the
win64 run equals the linux64 run to 1e-12 of each output's scale. mingw-w64 links its own
exp/log/pow/cos, which differ from glibc's in the last bit now and then: the largest
differences are printed (pytest -s) for the platform table of docs/fmus.md. Per sample,
P_fb (the PI's output, a difference of nearly equal resistances) can differ by more than
1e-12 relative where it crosses zero; relative to its scale it stays near 1e-15.
"""
import dataclasses
import zipfile

import numpy as np
import pytest

from sma_fmu.cosim.loop import run_library
from sma_fmu.cosim.scenario import load_scenario, resolve_scenarios
from sma_fmu.systems.closed_loop import closed_loop
from sma_fmu.systems.comparison import deviation
from sma_fmu.systems.hosts import loop_series
from sma_fmu.systems.loop_host import run_loop_host
from system_needs import needs

pytestmark = needs("gcc", "mingw-w64")
TOLERANCE = 1e-12
SCENARIOS = ("setpoints-pwm-pi+ff-adaptive", "load-step-pi+ff-adaptive-minor-loop")


def _scenario(name):
    return load_scenario(resolve_scenarios([name])[0])


@pytest.fixture(scope="module")
def native_dir(native_fmus):
    folder = native_fmus["SmaActuator"].parent
    for path in native_fmus.values():
        with zipfile.ZipFile(path) as archive:
            names = archive.namelist()
        assert f"binaries/win64/{path.stem}.dll" in names, f"{path}: no win64 binary"
    return folder


@pytest.fixture(scope="module")
def linux_runs(native_dir, tmp_path_factory):
    """{scenario: (system, samples)} of the linux64 loop host."""
    runs = {}
    for name in SCENARIOS:
        scenario = _scenario(name)
        system = closed_loop(scenario, native_dir)
        samples, logs, _ = run_loop_host(system, scenario.steps, tmp_path_factory.mktemp(name))
        assert [entry for entry in logs if entry[0] >= 2] == []  # no discard, error or fatal
        runs[name] = system, samples
    return runs


@pytest.mark.parametrize("name", SCENARIOS)
def test_the_linux64_loop_host_is_the_library_loop(linux_runs, name):
    system, samples = linux_runs[name]
    scenario = system.scenario
    assert {c.model for c in system.components} >= {"SmaActuator", "SmaFeedforward",
                                                    "SmaPiController", "SmaScenarioSignals"}
    data = loop_series(scenario, samples, scenario.steps)
    assert deviation(data, run_library(scenario).data) == 0.0  # the C runtime is the library
    assert np.ptp(data["R"]) > 1.0 and np.ptp(data["load"]) > 0.1  # the loop really moved


def test_the_loop_host_refuses_a_step_the_fmus_refuse(native_dir, tmp_path):
    """A refused FMI call (T_start = nan) stops the host, naming the component and the call:
    a run is never silently cut short."""
    from sma_fmu.fmi.hosts import CHostError

    scenario = _scenario("heavy-pi")
    bad = dataclasses.replace(scenario, T_start=float("nan"))
    with pytest.raises(CHostError, match=r"plant\.fmi2ExitInitializationMode returned 3"):
        run_loop_host(closed_loop(bad, native_dir), 10, tmp_path)


@needs("wine64")
@pytest.mark.parametrize("name", SCENARIOS)
def test_win64_binaries_under_wine_step_the_loop_as_linux64(linux_runs, wine, name, tmp_path):
    system, linux = linux_runs[name]
    scenario = system.scenario
    assert scenario.drive.pwm or name != SCENARIOS[0]  # the first one has all five FMUs
    windows, logs, _ = run_loop_host(system, scenario.steps, tmp_path, windows=wine)
    assert [entry for entry in logs if entry[0] >= 2] == []
    print(f"\n{name}: win64 (wine64) against linux64, {scenario.steps + 1} samples:"
          f" largest difference per sample, relative | over the output's largest magnitude")
    differs = 0
    for column, values in linux.items():
        a, b = np.asarray(values, float), np.asarray(windows[column], float)
        assert a.shape == b.shape == (scenario.steps + 1,)
        assert np.array_equal(np.isnan(a), np.isnan(b))
        a, b = np.nan_to_num(a), np.nan_to_num(b)
        difference = np.abs(a - b)
        scale = max(np.max(np.abs(a)), np.max(np.abs(b)))
        magnitude = np.maximum(np.abs(a), np.abs(b))
        per_sample = np.max(np.divide(difference, magnitude, out=np.zeros_like(a), where=difference > 0))
        over_scale = np.max(difference) / scale if scale > 0 else 0.0
        differs += int(np.count_nonzero(difference))
        print(f"  {column:<10}{per_sample:10.2e}  | {over_scale:9.2e}")
        assert over_scale <= TOLERANCE, (column, over_scale)
    assert np.ptp(linux["R"]) > 1.0
    print(f"  samples that differ at all: {differs}")


@needs("wine64")
def test_the_c_master_runs_the_win64_build_under_wine(native_dir, wine, tmp_path):
    """``--master c`` with the win64 host and DLLs: every row (binary frames on a Windows
    stdout), equal to the linux64 C master to 1e-12 of each column's scale (mingw-w64's
    libm), and a discard mid-run named with the rows up to it, as on linux64."""
    from sma_fmu.systems.c_master import CMasterError, run_c_master
    from test_c_master import DISCARD

    scenario = _scenario(SCENARIOS[0])
    linux = run_c_master(scenario, native_dir).data
    windows = run_c_master(scenario, native_dir, windows=wine).data
    assert windows.dtype == linux.dtype and len(windows) == scenario.steps + 1
    for name in linux.dtype.names:
        a, b = linux[name].astype(float), windows[name].astype(float)
        assert np.array_equal(np.isnan(a), np.isnan(b)), name
        a, b = np.nan_to_num(a), np.nan_to_num(b)
        assert np.max(np.abs(a - b)) <= TOLERANCE * max(np.max(np.abs(a)), 1e-300), name
    (tmp_path / "discard.toml").write_text(DISCARD.format(stop=1.0))
    with pytest.raises(CMasterError, match=r"C master \(win64, wine\): plant: fmi2DoStep failed "
                                           r"\(fmi2Discard\) at t = 0.5 s") as caught:
        run_c_master(load_scenario(tmp_path / "discard.toml"), native_dir, windows=wine)
    assert len(caught.value.rows) == 501


@needs("wine64")
def test_the_win64_c_master_writes_the_csv_the_recorder_would(native_dir, wine, tmp_path):
    """Under wine the win64 host writes the CSV's rows too (mingw-w64's printf only where
    format_g10 falls back): the file is the Python recorder's text of the win64 run's rows,
    byte for byte, and its "%.10g" is Python's on the edge cases and random doubles."""
    from sma_fmu.cosim.recording import RunRecorder
    from sma_fmu.systems.c_master import run_c_master
    from test_c_master import _g10, _PythonCsv, g10_cases

    values = g10_cases(count=20_000, seed=7)
    assert _g10(values, windows=wine) == ["%.10g" % v for v in values]
    scenario = _scenario(SCENARIOS[0])
    texts = []
    for kind, recorder_class in (("c", RunRecorder), ("python", _PythonCsv)):
        folder = tmp_path / kind
        folder.mkdir()
        recorder = recorder_class(scenario, folder, 3, "csv")
        run_c_master(scenario, native_dir, recorder, windows=wine)
        recorder.close()
        texts.append((folder / "timeseries.csv").read_bytes())
    assert texts[0] == texts[1] and texts[0].count(b"\n") == 1 + len(range(0, scenario.steps + 1, 3))
