"""Pictures and displays of mechanisms and sweeps: matplotlib drawings, SVG, DXF, the HTML
page, the notebook's rich displays, and the columns and numbers of tables as a reader sees
them. A floor above the algorithms (it solves through `kincas.analysis`, never the other
way) and below the command line, which writes these views to files.

The declarations and results do not know how they are drawn: `import kincas` gives
`Mechanism` and `Sweep` the Jupyter displays below. They load `kincas.views.notebook` when a
notebook first asks, so `import kincas` stays cheap.

>>> import kincas
>>> kincas.Mechanism._repr_svg_ is mechanism_svg_display, kincas.Sweep._repr_html_ is sweep_html_display
(True, True)
"""
from __future__ import annotations


def mechanism_svg_display(self) -> str | None:
    """Jupyter's display of a Mechanism: drawn at its first pose (`kincas.views.notebook`;
    the drawing solves it, so it is built only when a notebook asks)."""
    try:
        from .notebook import mechanism_svg
        return mechanism_svg(self)
    except Exception:  # a display must never raise: Jupyter falls back to repr
        return None


def sweep_html_display(self) -> str:
    """Jupyter's display of a Sweep: the summary and small plots of the quantities."""
    from .notebook import sweep_html
    return sweep_html(self)

