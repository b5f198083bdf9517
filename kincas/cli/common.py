"""What every command of the command line shares: exit statuses, the progress bar, units and
JSON lists of the scene's quantities."""
from __future__ import annotations

import sys

from .._launch import EXIT_INTERRUPTED  # noqa: F401  (130: one definition, usable while kincas loads)
from ..units import json_list as _list, param_unit, unit_label  # noqa: F401  (_list: JSON, NaN -> null)
from ..views.columns import _force_unit, quantity_unit as _unit  # noqa: F401  (units of the printed tables)

EXIT_OK, EXIT_SCENE, EXIT_UNSOLVED = 0, 2, 3


def progress_for(args):
    """A progress callback for long runs on a terminal; None when piped or with --json."""
    if getattr(args, "json", False) or getattr(args, "no_progress", False) or not sys.stderr.isatty():
        return None
    try:
        from .progress import Progress
    except ModuleNotFoundError:
        return None
    return Progress(stream=sys.stderr)


def _param_unit(sc, name: str) -> str:
    """A parameter's unit in the scene's units (kincas/units.py)."""
    return param_unit(sc.study.units, sc.mechanism, name)
