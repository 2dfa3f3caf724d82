"""The comparison figure's right margin: its outside legends stay inside the figure, without a layout pass."""
import pytest

pytest.importorskip("matplotlib")

from matplotlib.backends.backend_agg import FigureCanvasAgg  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402

from sma_fmu.cosim.plots import _legend_margin  # noqa: E402


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
