"""`kincas range SCENE.toml`: the range of motion of each input and its limits
(kincas/analysis/singular.py does the work)."""
from __future__ import annotations

import sys

from ..analysis.singular import input_range
from ..errors import ModelError, SceneError
from .scene import load


def cli_arguments(ap):
    ap.add_argument("scene", help="the scene file (TOML)")
    ap.add_argument("--input", help="the input whose range is wanted (default: every input)")
    ap.add_argument("--json", action="store_true", help="print one JSON object")


def cli_run(args) -> int:
    """Range of motion of each input (the others held at their first values) on the branch
    of the scene's first pose; limits located to rounding precision."""
    import json
    import math

    sc = load(args.scene)
    m = sc.mechanism
    keys = [i.key for i in m.inputs]
    if args.input and args.input not in keys:
        raise SceneError(f"--input: {args.input!r} is not an input of the scene (inputs: {keys})")
    start = {k: float(v[0]) for k, v in sc.study.inputs.items()}
    out, text = {}, []
    for i, key in enumerate(keys):
        if args.input and key != args.input:
            continue
        angle = m.inputs[i].is_angle  # (a joint's angle too: J.angle, J.angle1)
        conv = math.degrees if (angle and sc.study.deg) else float
        unit = sc.study.units.get("angle", "deg") if angle else sc.study.units.get("length", "")
        try:
            r = input_range(m, start, key)
        except ModelError:
            raise  # a wrong scene (exit 2), not an unsolvable pose
        except ValueError:
            print(f"kincas: the mechanism does not assemble at its first pose ({key} = "
                  f"{conv(start[key]):.12g} {unit})", file=sys.stderr)
            return 3
        out[key] = {"from": conv(r.low), "to": conv(r.high), "full_turn": r.full_turn,
                    "start": conv(r.start),
                    "limits": [{"kind": k, "input": conv(v)} for k, v in r.limits]}
        if r.full_turn:
            text.append(f"{key}: a full turn (no limit on this branch)")
        else:
            text.append(f"{key}: from {conv(r.low):.12g} to {conv(r.high):.12g} {unit}"
                        + "".join(f"\n  {k} at {conv(v):.12g} {unit}" for k, v in r.limits))
    if args.json:
        print(json.dumps({"title": sc.study.title, "units": sc.study.units, "ranges": out}))
    else:
        print(sc.study.title or "kincas range")
        print("\n".join(text))
    return 0
