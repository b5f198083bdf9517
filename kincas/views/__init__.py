"""Pictures and displays of mechanisms and sweeps: matplotlib drawings, SVG, DXF, the HTML
page, the notebook's rich displays, and the columns and numbers of tables as a reader sees
them. A floor above the algorithms (it solves through `kincas.analysis`, never the other
way) and below the command line, which writes these views to files.

The declarations and results do not know how they are drawn: `register()`, called by
`import kincas`, gives `Mechanism` and `Sweep` their Jupyter displays. It imports nothing
itself (the displays load `kincas.views.notebook` when a notebook first asks), so
`import kincas` stays cheap.

>>> import kincas
>>> kincas.Mechanism._repr_svg_ is _mechanism_svg, kincas.Sweep._repr_html_ is _sweep_html
(True, True)
"""
from __future__ import annotations


def _mechanism_svg(self) -> str | None:
    """Jupyter's display of a Mechanism: drawn at its first pose (`kincas.views.notebook`;
    the drawing solves it, so it is built only when a notebook asks)."""
    try:
        from .notebook import mechanism_svg
        return mechanism_svg(self)
    except Exception:  # a display must never raise: Jupyter falls back to repr
        return None


def _sweep_html(self) -> str:
    """Jupyter's display of a Sweep: the summary and small plots of the quantities."""
    from .notebook import sweep_html
    return sweep_html(self)


def register() -> None:
    """Give `Mechanism` and `Sweep` their notebook displays (idempotent)."""
    from ..model.mechanism import Mechanism
    from ..results import Sweep
    Mechanism._repr_svg_ = _mechanism_svg
    Sweep._repr_html_ = _sweep_html
