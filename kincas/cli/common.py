"""What every command of the command line shares: exit statuses, the progress bar, units and
JSON lists of the scene's quantities."""
from __future__ import annotations

import sys

from ..units import json_list as _list, param_unit, unit_label  # noqa: F401  (_list: JSON, NaN -> null)

EXIT_OK, EXIT_SCENE, EXIT_UNSOLVED, EXIT_INTERRUPTED = 0, 2, 3, 130


def progress_for(args):
    """A progress callback for long runs on a terminal; None when piped or with --json."""
    if getattr(args, "json", False) or getattr(args, "no_progress", False) or not sys.stderr.isatty():
        return None
    try:
        from .progress import Progress
    except ModuleNotFoundError:
        return None
    return Progress(stream=sys.stderr)


def _unit(sc, name: str) -> str:
    """The unit of quantity `name` in the scene's units (kincas/units.py)."""
    return unit_label(sc.study.units, sc.mechanism, name, _force_unit)


def _force_unit(name: str, L: str) -> str | None:
    """Units of force quantities and curvature (None for others). The scene names no mass
    unit, so a force is written `force` (N with masses in kg and SI lengths, or in t and mm)."""
    from ..core.dynamics import _EFFORT
    m = _EFFORT.match(name)
    if m:
        angular = m["key"].endswith(".angle")
        return f"force·{L}" if angular and L else "force"
    if name.startswith("reaction(") or name in ("shaking.x", "shaking.y"):
        return "force"
    if name == "shaking.moment":
        return f"force·{L}" if L else "force"
    if name.endswith(".curvature"):
        return f"1/{L}" if L else ""
    return None


def _param_unit(sc, name: str) -> str:
    """A parameter's unit in the scene's units (kincas/units.py)."""
    return param_unit(sc.study.units, sc.mechanism, name)
