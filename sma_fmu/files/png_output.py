"""A matplotlib figure as PNG bytes: how every figure the package writes is rendered.

Figures are drawn on :class:`matplotlib.figure.Figure` objects (no pyplot, no backend
switch); the callers write the bytes where they belong (results folders, FMU archives).
"""
import io

__all__ = ["png_bytes", "tight_layout"]


def tight_layout(figure):
    """``figure.tight_layout()``, leaving no layout engine behind: matplotlib leaves a
    placeholder one, and savefig then draws the whole figure once more before it renders
    it (a third of a figure's time)."""
    figure.tight_layout()
    figure.set_layout_engine(None)


def png_bytes(figure, dpi=None, tight=False):
    """The PNG bytes of ``figure``: at ``dpi`` (None: matplotlib's savefig default), after
    :func:`tight_layout` if ``tight``."""
    if tight:
        tight_layout(figure)
    buffer = io.BytesIO()
    figure.savefig(buffer, format="png", dpi=dpi)
    return buffer.getvalue()
