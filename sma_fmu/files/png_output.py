"""A matplotlib figure as PNG bytes: how every figure the package writes is rendered.

Figures are drawn on :class:`matplotlib.figure.Figure` objects (no pyplot, no backend
switch); the callers write the bytes where they belong (results folders, FMU archives).
"""
import io

__all__ = ["png_bytes"]


def png_bytes(figure, dpi=None, tight=False):
    """The PNG bytes of ``figure``: at ``dpi`` (None: matplotlib's savefig default), after
    ``tight_layout()`` if ``tight``."""
    if tight:
        figure.tight_layout()
    buffer = io.BytesIO()
    figure.savefig(buffer, format="png", dpi=dpi)
    return buffer.getvalue()
