"""Shared helpers of the kincas tests: run the CLI in-process, write scenes to files."""
from __future__ import annotations

import json
import math
import os
import re
import signal
import sys
from pathlib import Path

import numpy as np

# A test runner started in the background by a shell without job control (`cmd &` in a script)
# inherits SIGINT ignored, and so would every process it starts: the Ctrl-C tests (they send
# SIGINT to kincas commands and to this process) need Python's own handler, which an exec'd
# child then gets back as the default disposition.
if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
    signal.signal(signal.SIGINT, signal.default_int_handler)

# Compiled kernels take libm's sines and cosines in the tests, as CasADi's virtual machine
# does, so that the many tests holding a compiled sweep to its virtual-machine form (or a
# sweep to the same sweep run before a background compile landed) can ask for the same bits.
# By default kincas compiles fdlibm's (kincas/core/c_source.py), within an ulp: tested by
# tests/test_fdlibm_kernels.py and tests/test_c_source.py, which unset this.
os.environ.setdefault("KINCAS_LIBM_TRIG", "1")

TESTS = Path(__file__).resolve().parent
ROOT = TESTS.parent
EXAMPLES = ROOT / "examples"

# The tests import closed_forms and this module by name, and kincas from the work tree when it
# is not installed, whatever pytest's import mode.
for _path in (str(TESTS), str(ROOT)):
    if _path not in sys.path:
        sys.path.insert(0, _path)


def run_cli(capsys, *args):
    """Run `kincas.cli.main(args)` in-process: (exit status, parsed JSON or the text of
    standard output, standard error)."""
    from kincas.cli import main

    capsys.readouterr()  # drop what was printed before
    try:
        code = main([str(a) for a in args])
    except SystemExit as exc:  # e.g. argparse; the status is what a user would see
        code = exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 1)
    out, err = capsys.readouterr()
    try:
        result = json.loads(out)
    except ValueError:
        result = out
    return code, result, err


# --------------------------------------------------------------------------- TOML writing

def _key(key: str) -> str:
    return key if re.fullmatch(r"[A-Za-z0-9_-]+", key) else json.dumps(key)


def _value(v) -> str:
    if isinstance(v, (bool, np.bool_)):
        return "true" if v else "false"
    if isinstance(v, (int, np.integer)):
        return str(int(v))
    if isinstance(v, (float, np.floating)):
        v = float(v)
        if math.isnan(v):
            return "nan"
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return repr(v)
    if isinstance(v, str):
        return json.dumps(v)
    if isinstance(v, (list, tuple, np.ndarray)):
        return "[" + ", ".join(_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{ " + ", ".join(f"{_key(k)} = {_value(x)}" for k, x in v.items()) + " }"
    raise TypeError(f"cannot write {v!r} as TOML")


def dump_toml(scene: dict, comment: str = "scene written by the kincas tests") -> str:
    """The scene as TOML text: scalars first, then one [table] per dict, [[array]] per list of
    dicts; nested dicts as inline tables. Enough for scene files."""
    head, tables = [f"# {comment}"], []
    for key, v in scene.items():
        if isinstance(v, dict):
            tables.append(f"\n[{_key(key)}]")
            tables += [f"{_key(k)} = {_value(x)}" for k, x in v.items()]
        elif isinstance(v, list) and v and all(isinstance(x, dict) for x in v):
            for item in v:
                tables.append(f"\n[[{_key(key)}]]")
                tables += [f"{_key(k)} = {_value(x)}" for k, x in item.items()]
        else:
            head.append(f"{_key(key)} = {_value(v)}")
    return "\n".join(head + tables) + "\n"


def write_scene(tmp_path: Path, scene: dict | str, name: str = "scene.toml") -> Path:
    """Write a scene (a dict, or TOML text as is) to tmp_path/name and return the path."""
    path = Path(tmp_path) / name
    path.write_text(scene if isinstance(scene, str) else dump_toml(scene), encoding="utf-8")
    return path
