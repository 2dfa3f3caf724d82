"""A bench scenario (sensor noise and ADC, a binding current limit) in the system tools: the SSP
package in libcosim and Ecos (Jacobi: the driver reads the plant's R as it was at t_k, the
PI's sensor takes its k-th sample at the k-th step) and the container FMU in fmpy and libcosim
(Gauss-Seidel) match the library loop of their coupling to 1e-9 in every column, as the
paper's scenarios do; the SSP binds the sensor's and the limit's values."""
import dataclasses
import zipfile

import pytest

from sma_fmu.cosim.scenario import load_scenario, resolve_scenarios
from sma_fmu.systems.closed_loop import closed_loop
from sma_fmu.systems.comparison import compare_hosts
from sma_fmu.systems.ssp import SSD_NAME, write_ssp

TOLERANCE = 1e-9


@pytest.fixture(scope="module")
def bench():
    scenario = load_scenario(resolve_scenarios(["load-step-bench-pi+ff-adaptive"])[0])
    drive = dataclasses.replace(scenario.drive, I_max_A=0.3)      # binding
    return dataclasses.replace(scenario, stop_time_s=2.2, drive=drive)


def test_the_ssp_binds_the_sensor_and_the_limit(bench, fmu_dir, tmp_path):
    path = write_ssp(closed_loop(bench, fmu_dir), tmp_path / "bench.ssp")
    with zipfile.ZipFile(path) as archive:
        ssd = archive.read(SSD_NAME).decode()
    for name in ("noise_ohm_rms", "full_scale_ohm", "bits", "seed", "modulation",
                 "I_max_A", "V_max_V"):
        assert f'name="{name}"' in ssd, name
    assert 'startElement="plant" startConnector="R" endElement="driver" endConnector="R"' in ssd


def test_the_system_tools_run_the_bench_loop(bench, fmu_dir):
    rows = compare_hosts(bench, fmu_dir)
    runs = {row["run"]: row for row in rows}
    assert {"libcosim (ssp)", "ecos (ssp)", "fmpy (container)", "libcosim-container (container)"} \
        <= set(runs)
    for row in rows:
        assert row["deviation"] <= TOLERANCE, row
