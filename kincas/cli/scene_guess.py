"""A scene's TOML text with its `[guess]` table replaced by an assembly mode's, as
`kincas modes --write DIR` writes one scene per mode (the search itself, in
kincas/analysis/modes.py, takes a mechanism and never reads a scene)."""
from __future__ import annotations

import re
import tomllib

from ..analysis.modes import Mode
from ..errors import SceneError

_GUESS_HEADER = re.compile(r"^\s*\[\s*guess\s*\]\s*(#.*)?$")
_ANY_HEADER = re.compile(r"^\s*\[")
_FILLER = re.compile(r"^\s*(#.*)?$")


def scene_with_guess(text: str, mode: Mode, note: str = "") -> str:
    """The scene's TOML text with its `[guess]` table replaced by the mode's (appended when
    the scene has none); everything else is kept as written.

    >>> import numpy as np
    >>> from kincas.analysis.modes import Mode
    >>> md = Mode(np.zeros(1), ("a",), {"C": (3.5, -2.0)}, {}, 0.0, 1)
    >>> print(scene_with_guess('a = 1\\n[guess]\\nC = [1, 2]\\n\\n[output]\\n', md), end="")
    a = 1
    [guess]
    C = [3.5, -2]
    <BLANKLINE>
    [output]
    """
    lines = text.splitlines(keepends=True)
    if lines and not lines[-1].endswith("\n"):
        lines[-1] += "\n"
    block = ([f"# {note}\n"] if note else []) + mode.guess_block().splitlines(keepends=True)
    start = next((i for i, ln in enumerate(lines) if _GUESS_HEADER.match(ln)), None)
    if start is None:
        lines += ["\n"] + block
    else:
        end = next((j for j in range(start + 1, len(lines)) if _ANY_HEADER.match(lines[j])), len(lines))
        while end > start + 1 and _FILLER.match(lines[end - 1]):
            end -= 1  # blank lines and comments before the next table belong to it
        lines[start:end] = block
    out = "".join(lines)
    try:
        written = tomllib.loads(out).get("guess", {})
    except tomllib.TOMLDecodeError:
        written = None
    if written is None or set(written) != set(mode.points):
        raise SceneError("[guess]: not written as a [guess] table, so it cannot be replaced; "
                         "copy the printed [guess] block into the scene instead")
    return out
