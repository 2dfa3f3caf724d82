"""sma-fmu bench's native section (sma_fmu/bench/native.py) is measured and reported: the
native SmaActuator step in the C host and the fmpy master, the library plant step, the
pythonfmu SmaActuator in the same C host, the HIL closed loop of the five native FMUs in the
C loop host. Speed is never asserted: only that every case ran and is reported."""
import math

from sma_fmu.bench.native import NATIVE_TARGETS, native_costs, native_lines
from system_needs import needs


@needs("gcc")
def test_the_native_section_is_measured_and_reported(fmus, native_fmus, params, tmp_path):
    native = native_costs(fmus, native_fmus, params, runs=2, folder=tmp_path, loop_steps=20_000)
    assert set(native["samples_us"]) == {"library plant step", "native SmaActuator, C host",
                                         "pythonfmu SmaActuator, C host",
                                         "native SmaActuator, fmpy master"}
    for values in native["samples_us"].values():
        assert len(values) == 2 and all(math.isfinite(v) and v > 0 for v in values)
    assert len(native["loop_runs"]) == 2 and native["loop_steps"] == 20_000
    loop = native["loop"]
    assert 0 < loop["p50_us"] <= loop["p99_us"] <= loop["p99_9_us"] <= loop["max_us"]
    for row in native["ratios"].values():
        assert row["min"] <= row["median"] <= row["max"] and row["runs"] == 2
    text = "\n".join(native_lines(native))
    for name in [*NATIVE_TARGETS, "native SmaActuator in the fmpy master / library plant step"]:
        assert name.split(",")[0].replace(" p99.9 [us]", "") in text
    assert text.count("target") == len(NATIVE_TARGETS) and "20000 steps of 1 ms" in text
