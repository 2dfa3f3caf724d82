"""``sma-fmu bench --only stroke``: the stroke map's cost table (numbers printed, not asserted)."""
from sma_fmu.bench.stroke import c_map_costs, map_costs, stroke_lines
from system_needs import needs


def test_the_stroke_bench_measures_every_case_and_counts_the_rounds():
    costs, rounds = map_costs(1)
    assert len(costs) == 4 and all(ns > 0.0 for ns in costs.values())
    assert 1.0 <= rounds <= 200.0   # one inverse at least, at most the cap (ROOT_CAP)
    lines = stroke_lines({"map_ns_per_step": costs, "flexinol_inverses_per_solve": rounds,
                          "library_wall_s": {"a": {"stroke": 1.0, "mapped_beforehand": 0.5}}})
    assert lines[0].startswith("stroke map, CPU per step") and len(lines) == 8


@needs("gcc")
def test_the_stroke_bench_times_the_c_map_of_both_wires_and_the_c_masters_table():
    costs = c_map_costs(1)
    assert set(costs) == {"moving stroke, reference wire (closed form)",
                          "moving stroke, Flexinol fit (secant on T)",
                          "R_ref(t) of the 0.5 Hz profile (trend + map)"}
    assert all(ns > 0.0 for ns in costs.values())
