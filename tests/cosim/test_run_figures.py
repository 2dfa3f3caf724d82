"""Run figures: a kept figure draws each run as a new one would; the comparison figure's
right margin keeps its outside legends inside the figure, without a layout pass."""
import dataclasses

import pytest

pytest.importorskip("matplotlib")

from matplotlib.backends.backend_agg import FigureCanvasAgg  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402

from sma_fmu.cosim import plots  # noqa: E402
from sma_fmu.cosim.loop import run_library  # noqa: E402
from sma_fmu.cosim.scenario import load_scenario  # noqa: E402
from sma_fmu.files.package_data import shipped_file  # noqa: E402
from sma_fmu.cosim.plots import _legend_margin  # noqa: E402


def _run(name, stop_time_s):
    scenario = load_scenario(shipped_file("scenarios", f"{name}.toml"))
    scenario = dataclasses.replace(scenario, stop_time_s=stop_time_s)
    return run_library(scenario).data, scenario


def test_a_kept_run_figure_draws_each_run_as_a_new_figure(tmp_path):
    """The same PNG bytes, whatever the kept figure drew before (other limits, load
    changes, metrics window, room temperature, a run with the feedforward's lines before
    one without them and after it)."""
    runs = [_run("load-step-pi+ff-adaptive", 12.0), _run("heavy-pi", 4.0),
            _run("heavy-pi+ff-fixed", 1.5), _run("load-step-pi+ff-adaptive", 21.0)]
    vars(plots._KEPT).clear()
    for index, (data, scenario) in enumerate(runs):
        plots.plot_run(data, scenario, tmp_path / f"kept-{index}.png")
    assert sorted(vars(plots._KEPT)) == ["run"]   # one figure, with the feedforward's lines or without
    for index, (data, scenario) in enumerate(runs):
        vars(plots._KEPT).clear()
        plots.plot_run(data, scenario, tmp_path / f"new-{index}.png")
        kept = (tmp_path / f"kept-{index}.png").read_bytes()
        assert kept == (tmp_path / f"new-{index}.png").read_bytes(), index
    assert (tmp_path / "new-0.png").read_bytes() != (tmp_path / "new-3.png").read_bytes()


@pytest.mark.parametrize("label", ["pi", "a-scenario-name-" * 6])
def test_outside_legend_fits_the_figure(label):
    figure = Figure(figsize=(12, 10))
    axis = figure.add_subplot(1, 1, 1)
    axis.plot([0.0, 1.0], [0.0, 1.0], label=label)
    legend = axis.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8, borderaxespad=0)
    right = _legend_margin(figure, [legend], 0.063, 0.817)
    figure.subplots_adjust(left=0.063, right=right)
    renderer = FigureCanvasAgg(figure).get_renderer()
    box = legend.get_window_extent(renderer)
    assert box.x0 > axis.get_window_extent(renderer).x1   # outside the axes, to its right
    assert box.x1 < figure.bbox.width                       # and inside the figure
    assert right <= 0.817
    assert (right < 0.6) == (len(label) > 40)              # a long label takes room, a short one none


def test_a_kept_comparison_figure_draws_each_group_as_a_new_figure(tmp_path):
    """The same PNG bytes, whatever the kept axes drew before (other runs, labels, windows)."""
    load_step = {"pi": _run("load-step-pi", 12.0)[0],
                 "pi+ff-adaptive": _run("load-step-pi+ff-adaptive", 12.0)[0]}
    heavy = {name: _run(f"heavy-{name}", 6.0)[0] for name in ("pi", "pi+ff-fixed", "pi+ff-adaptive")}
    groups = [(load_step, _run("load-step-pi", 12.0)[1], "load-step"),
              (heavy, _run("heavy-pi", 6.0)[1], "heavy")]
    vars(plots._KEPT).clear()
    for index, (runs, scenario, title) in enumerate(groups):
        plots.plot_comparison(runs, scenario, title, tmp_path / f"kept-{index}.png")
    for index, (runs, scenario, title) in enumerate(groups):
        vars(plots._KEPT).clear()
        plots.plot_comparison(runs, scenario, title, tmp_path / f"new-{index}.png")
        assert (tmp_path / f"kept-{index}.png").read_bytes() == (tmp_path / f"new-{index}.png").read_bytes()


def test_each_thread_keeps_figures_of_its_own(tmp_path):
    """A run figure drawn on another thread is that thread's, never the one this thread keeps
    (run_scenarios may be called from threads at once); its PNG is the same."""
    import threading

    data, scenario = _run("heavy-pi", 2.0)
    plots.plot_run(data, scenario, tmp_path / "here.png")
    mine = plots._KEPT.run
    theirs = []

    def draw():
        plots.plot_run(data, scenario, tmp_path / "there.png")
        theirs.append(plots._KEPT.run)

    thread = threading.Thread(target=draw)
    thread.start()
    thread.join()
    assert theirs and theirs[0] is not mine and plots._KEPT.run is mine
    assert (tmp_path / "here.png").read_bytes() == (tmp_path / "there.png").read_bytes()


def test_the_feedforward_lines_show_only_for_a_run_with_a_feedforward(tmp_path):
    """One kept figure draws runs with and without a feedforward: T_ref and P_ff are drawn
    and in the legends for the one, empty and out of the legends for the other."""
    vars(plots._KEPT).clear()
    runs = (("heavy-pi+ff-fixed", True), ("heavy-pi", False), ("heavy-pi+ff-fixed", True))
    for name, feedforward in runs:
        data, scenario = _run(name, 2.0)
        plots.plot_run(data, scenario, tmp_path / f"{name}.png")
        axes = plots._KEPT.run.axes
        legends = {text.get_text() for axis in axes for text in axis.get_legend().get_texts()}
        for label in ("T_ref (inverse model)", "P_ff (feedforward)"):
            assert (label in legends) == feedforward, (name, label)
            line = next(line for axis in axes for line in axis.lines
                        if line.get_label().lstrip("_") == label)
            assert (len(line.get_xdata()) > 0) == feedforward, (name, label)
        assert {"R", "T (wire)", "P applied", "P_fb (PI feedback)", "load"} <= legends
