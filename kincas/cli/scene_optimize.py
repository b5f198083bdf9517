"""The scene's `[optimize]` section read into the keywords of `kincas.optimize` (samples,
data and bounds in the scene's units, degrees where it says so), and run: what
`kincas optimize` does with a scene; the optimiser itself (kincas/synthesis/optimize.py)
takes a mechanism and plain values, and never reads a scene."""
from __future__ import annotations

import math

import numpy as np

from ..errors import ModelError
from ..synthesis.optimize import Optimization, optimize


FIELDS = {"vary", "minimize", "constraints", "data", "samples", "check_path", "max_iter", "curve"}
CURVE_FIELDS = {"point", "targets", "within", "order"}


def read_section(sc) -> dict:
    """The scene's `[optimize]` section as keywords of optimize(); SceneError naming the
    field. Samples, data and bounds are in the scene's units (degrees where it says so)."""
    from ..errors import SceneError

    t = sc.study.raw.get("optimize")
    if not isinstance(t, dict):
        raise SceneError("[optimize]: missing or not a table (give at least vary = { PARAMETER "
                         "= [low, high] } and minimize = \"EXPRESSION\")")
    problems = [f"[optimize]: unknown field {k!r} (expected one of {sorted(FIELDS)})"
                for k in t if k not in FIELDS]
    needed = ("vary",) if "curve" in t else ("vary", "minimize")
    problems += [f"[optimize] {k}: missing" for k in needed if k not in t]
    kw = {"vary": t.get("vary"), "minimize": t.get("minimize"), "data": t.get("data"),
          "constraints": t.get("constraints", []), "deg": sc.study.deg}
    if not isinstance(kw["constraints"], list) or not all(isinstance(c, dict) for c in kw["constraints"]):
        problems.append("[optimize] constraints: expected a list of { expr = \"...\", min = a, "
                        "max = b } (or [[optimize.constraints]] blocks)")
    if kw["data"] is not None and not isinstance(kw["data"], dict):
        problems.append("[optimize] data: expected a table of name = [values, one per sample]")
    if not isinstance(t.get("check_path", True), bool):
        problems.append("[optimize] check_path: expected true or false")
    mi = t.get("max_iter", 1000)
    if isinstance(mi, bool) or not isinstance(mi, int) or mi < 1:
        problems.append(f"[optimize] max_iter: expected a whole number >= 1, got {mi!r}")
    kw.update(check_path=t.get("check_path", True), max_iter=mi)
    if isinstance(kw["vary"], dict):
        kw["vary"] = {k: tuple(v) if isinstance(v, list) else v for k, v in kw["vary"].items()}
    samples = dict(sc.study.inputs)
    if "samples" in t:
        m = sc.mechanism
        if len(m.inputs) != 1:
            problems.append("[optimize] samples: only for a mechanism with one input (else the "
                            "samples are the [[inputs]] values)")
        else:
            s, k = t["samples"], (math.pi / 180 if m.inputs[0].is_angle and sc.study.deg else 1.0)
            if isinstance(s, dict) and set(s) == {"from", "to", "steps"} and all(
                    isinstance(s[x], (int, float)) and not isinstance(s[x], bool) for x in s) \
                    and isinstance(s["steps"], int) and s["steps"] >= 1:
                samples = {m.inputs[0].key: np.linspace(s["from"], s["to"], s["steps"]) * k}
            elif isinstance(s, list) and s and all(
                    isinstance(x, (int, float)) and not isinstance(x, bool) for x in s):
                samples = {m.inputs[0].key: np.array(s, dtype=float) * k}
            else:
                problems.append("[optimize] samples: expected { from = a, to = b, steps = n } "
                                "or a list of input values")
    if "curve" in t:
        if "samples" in t:
            problems.append("[optimize] samples: not with curve (the inputs at the targets "
                            "are fitted; give the curve's range as within = [low, high])")
        samples = _read_curve(sc, t["curve"], problems)
    if problems:
        raise SceneError(problems)
    kw["samples"] = samples
    return kw


def _read_curve(sc, c, problems):
    """[optimize.curve] as a Curve (None and problems appended when it is wrong)."""
    from ..synthesis.curve import Curve

    if not isinstance(c, dict):
        problems.append("[optimize] curve: expected a table { point = \"P\", targets = "
                        "[[x, y], ...] } (or an [optimize.curve] section)")
        return None
    bad = [f"[optimize] curve: unknown field {k!r} (expected one of {sorted(CURVE_FIELDS)})"
           for k in c if k not in CURVE_FIELDS]
    bad += [f"[optimize] curve: {k}: missing" for k in ("point", "targets") if k not in c]
    m = sc.mechanism
    if len(m.inputs) != 1:
        bad.append("[optimize] curve: only for a mechanism with one input")
    if not isinstance(c.get("point", ""), str):
        bad.append(f"[optimize] curve: point: expected a point's name, got {c['point']!r}")
    if bad:
        problems += bad
        return None
    inp = m.inputs[0]
    k = math.pi / 180 if inp.is_angle and sc.study.deg else 1.0
    within = c.get("within")
    if within is None:  # default: the range swept by the scene's [[inputs]]
        u = np.asarray(sc.study.inputs[inp.key], dtype=float)
        within = (float(u.min()), float(u.max())) if u.max() > u.min() else None
        if within is None and not inp.is_angle:
            problems.append(f"[optimize] curve: within: missing (the [[inputs]] of {inp.key} "
                            f"do not sweep a range)")
            return None
    elif isinstance(within, list) and len(within) == 2 and all(
            isinstance(x, (int, float)) and not isinstance(x, bool) for x in within):
        if not within[0] < within[1]:
            problems.append(f"[optimize] curve: within: expected [low, high] with low < high, "
                            f"got {within!r}")
            return None
        within = (within[0] * k, within[1] * k)
    try:
        return Curve(c["point"], c["targets"], within=within, order=c.get("order", "auto"))
    except ModelError as e:
        problems += [f"[optimize] {p}" for p in e.problems]
        return None


def run_scene(sc) -> Optimization:
    """Optimise as the scene's [optimize] section says (SceneError for a bad section)."""
    from ..errors import ModelError, SceneError

    kw = read_section(sc)
    sc.refuse_jerks([kw.get("minimize")] + list(kw.get("constraints", ())), "[optimize]")
    try:
        return optimize(sc.mechanism, kw.pop("samples"), rates=sc.study.rates,
                        accelerations=sc.study.accelerations, **kw)
    except ModelError as e:
        raise SceneError([f"[optimize] {p}" for p in e.problems]) from None
