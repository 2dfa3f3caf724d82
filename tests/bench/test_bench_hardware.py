"""sma-fmu bench --only hardware: the C timing programs run the very blocks and compensators
the Python timing runs (the sums of their outputs over a pass agree to the bit), and the
section's table names every block and compensator with both costs. No timing is asserted
(speed is the bench's to print)."""
import subprocess

import pytest

from sma_fmu.bench.compensator import (CASES, c_compensator_passes, compensator_costs,
                                       python_compensator_sum)
from sma_fmu.bench.hardware import BLOCKS, _python_blocks, c_costs, hardware_lines, python_costs
from sma_fmu.bench.inverse import timing_program
from system_needs import needs


@needs("gcc")
def test_the_c_program_computes_what_the_python_blocks_compute(tmp_path):
    program = timing_program(tmp_path, "hardware_timing")
    steps = 3000
    result = subprocess.run([str(program)], input=f"1 {steps}", capture_output=True, text=True,
                            check=True)
    c_sums = {line.split()[0]: float(line.split()[2]) for line in result.stdout.splitlines()}
    assert set(c_sums) == set(BLOCKS)
    for name, block in _python_blocks().items():
        total = 0.0
        for k in range(steps):
            total += block(k)
        assert c_sums[name] == total, name


@needs("gcc")
@pytest.mark.parametrize("case", sorted(CASES))
def test_the_c_compensator_program_steps_what_the_python_compensator_steps(tmp_path, case):
    program = timing_program(tmp_path, "compensator_timing")
    passes = c_compensator_passes(program, case, 2, steps=1500)
    assert len(passes) == 2 and passes[0][1] == passes[1][1]   # a fresh compensator each pass
    assert passes[0][1] == python_compensator_sum(case, steps=1500)
    assert passes[0][1] != 0.0


@needs("gcc")
def test_the_section_lists_every_block(tmp_path):
    costs = {"python_ns": python_costs(1, steps=200), "c_ns": c_costs(tmp_path, 1, steps=200)}
    compensators = compensator_costs(tmp_path, 1, steps=200)
    assert set(compensators) == set(CASES)
    assert all(value > 0 for row in compensators.values() for value in row.values())
    assert set(costs["python_ns"]) == set(costs["c_ns"]) == set(BLOCKS)
    assert all(value > 0 for table in costs.values() for value in table.values())
    row = {"library_s": 3.0, "c_s": 0.3, "ratio": 0.1, "min": 0.09, "max": 0.11, "runs": 1}
    lines = hardware_lines({"hardware": {"per_step": costs, "compensator_per_step": compensators,
                                         "c_master": {"x (parquet)": row}, "target": 0.25}})
    for text in [*BLOCKS.values(), *(label for label, _, _ in CASES.values())]:
        assert any(line.startswith(text) for line in lines)
    assert "meets target <= 0.25" in lines[-1]
    with pytest.raises(KeyError):
        hardware_lines({"hardware": {"per_step": {"python_ns": {}, "c_ns": {}}, "c_master": {},
                                     "target": 0.25}})
