"""`kincas modes SCENE.toml`: the distinct assembly modes at the scene's first pose, printed
as [guess] blocks or written as scenes (kincas/analysis/modes.py finds them)."""
from __future__ import annotations

import json
import math
import sys
from pathlib import Path

import numpy as np

from ..analysis.modes import find_modes
from ..core.tolerances import SAME_ASSEMBLY
from ..errors import OutputError, SceneError
from .scene import load
from .scene_guess import scene_with_guess
from ..model.names import is_angle_name


def cli_arguments(parser) -> None:
    """Arguments of `kincas modes`."""
    parser.add_argument("scene", help="the scene file (TOML)")
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    parser.add_argument("--starts", type=int, default=512,
                        help="number of scattered Newton starts (default 512)")
    parser.add_argument("--seed", type=int, default=0, help="seed of the scattered starts")
    parser.add_argument("--certify", action="store_true",
                        help="prove the list complete: every real assembly, by an exact solver "
                             '(msolve: pip install "kincas[certify]"; pins and slides only)')
    parser.add_argument("--write", metavar="DIR",
                        help="also write DIR/<scene>_mode<k>.toml: the scene with mode k's [guess]")


def cli_run(args) -> int:
    """Find the modes at the scene's first pose; print them (and write scenes with --write).
    Exit status 0 when at least one assembly was found, 3 when none."""
    if args.starts < 1:
        raise SceneError(f"--starts: expected a whole number >= 1, got {args.starts}")
    sc = load(args.scene)
    at = {k: float(v[0]) for k, v in sc.study.inputs.items()}
    if args.certify:
        modes = _certified(sc.mechanism, at)
        if modes is None:
            return 2
        at = dict(modes.inputs)  # the pose certified (rounded where it says so)
    else:
        modes = find_modes(sc.mechanism, at, starts=args.starts, seed=args.seed)
    if not sc.mechanism.guess and modes:
        modes = _solve_starts_on(sc, modes)
    deg = sc.study.deg
    user_in = {k: (math.degrees(v) if deg and is_angle_name(k) else v) for k, v in at.items()}
    user_ang = [{lk: (math.degrees(a) if deg else a) for lk, a in md.angles.items()} for md in modes]
    if args.write:
        _write_scenes(args.scene, args.write, modes)
    if args.json:
        doc = {"title": sc.study.title, "units": sc.study.units, "inputs": user_in,
               "certified": modes.certified,
               "modes": [{"points": {p: list(xy) for p, xy in md.points.items()},
                          "angles": ang, "residual": md.residual, "orientation": md.orientation,
                          "from_guess": md.from_guess, "guess": md.guess_block(),
                          **_certificate(md)}
                         for md, ang in zip(modes, user_ang)]}
        if modes.certified:
            doc.update(count=modes.count, rounded=modes.rounded, rejected=modes.rejected,
                       discarded=modes.discarded, positive_dimension=modes.positive_dimension)
        else:
            doc.update(starts=args.starts, seed=args.seed)
        json.dump(doc, sys.stdout, allow_nan=False)
        sys.stdout.write("\n")
    else:
        _print_modes(sc, modes, user_in, user_ang, args)
    return 0 if modes else 3


def _certified(m, at):
    """The certified modes, or None after one line on why there are none (exit 2): a
    constraint that is not polynomial, or no solver."""
    from ..analysis.certify import certify_modes
    from ..analysis.certify_msolve import SolverFailed, SolverMissing
    from ..core.polynomial_planar import NotPolynomial, refusal
    why = refusal(m)
    try:
        if why is None:
            return certify_modes(m, at)
    except (SolverMissing, SolverFailed, NotPolynomial) as e:
        why = str(e)
    print(f"kincas: --certify: {why}", file=sys.stderr)
    return None


def _certificate(md) -> dict:
    """A certified mode's box half-width, multiplicity, flag (and a note if any)."""
    if not hasattr(md, "halfwidth"):
        return {}
    out = {"halfwidth": md.halfwidth, "multiplicity": md.multiplicity, "flag": md.flag}
    return {**out, "note": md.note} if md.note else out


def _print_modes(sc, modes, user_in, user_ang, args):
    units = sc.study.units
    unit = {k: units.get("angle", "deg") if is_angle_name(k) else
            units.get("length", "") if k.endswith(".s") else "" for k in user_in}
    at = ", ".join(f"{k} = {v:.6g}" + (f" {unit[k]}" if unit[k] else "") for k, v in user_in.items())
    print(sc.study.title or "kincas")
    n = len(modes)
    how = (f"certified: every real assembly (msolve), count {n}" if modes.certified
           else f"{args.starts} starts, seed {args.seed}; multistart search, not certified")
    print(f"{n} assembly mode{'s' if n != 1 else ''}" + (f" at {at}" if at else "") + f" ({how})")
    for note in getattr(modes, "rounded", []):
        print(f"  the certificate is for the rounded pose: {note}")
    for note in getattr(modes, "rejected", []):
        print(f"  rejected: {note}")
    if getattr(modes, "discarded", []):
        print(f"  discarded: {len(modes.discarded)} real solutions of the kept equations that break an "
              f"implied one (not assemblies; --json lists them)")
    size = sc.mechanism.size()
    pts = [np.ravel(list(md.points.values())) for md in modes]
    if any(np.abs(a - b).max(initial=0.0) <= SAME_ASSEMBLY * size for i, a in enumerate(pts) for b in pts[:i]):
        # in space: a body's spin about the line of its points
        print("  some modes have the same points (they differ in a body's turn about the line of its "
              "points): a [guess] of points cannot pick between them")
    for k, (md, ang) in enumerate(zip(modes, user_ang), 1):
        mark = "" if not md.from_guess else ("  <- the scene's [guess] gives this one" if sc.mechanism.guess
                                             else "  <- `kincas solve` starts on this one (no [guess])")
        box = _certificate(md)
        box = (f", box half-width {box['halfwidth']:.1e}, multiplicity {box['multiplicity']}"
               + (f" ({box['flag']})" if box["flag"] else "") + (f"; {box['note']}" if "note" in box else "")
               if box else "")
        print(f"\nmode {k} of {n}: residual {md.residual:.1e}, orientation {md.orientation:+d}{box}{mark}")
        if ang:  # (a mechanism of bars and points alone has no angle to show)
            print("  angles: " + ", ".join(f"{lk} {a:.6g}" for lk, a in ang.items())
                  + f" {units.get('angle', 'deg')}")
        print(md.guess_block(), end="")
    if getattr(modes, "positive_dimension", False):
        print("infinitely many assemblies at this pose: a link is free to turn (no finite list)")
    elif not modes:
        print("no assembly" + (" (certified)" if modes.certified else " found")
              + ": the mechanism cannot be put together at this input")


def _solve_starts_on(sc, modes):
    """Without [guess], the sweep may leave the default assembly for one that runs every
    pose (an "assembly" event, kincas/analysis/choice.py): that one is marked instead."""
    from dataclasses import replace

    chosen = next((e for e in sc.run().events if e["kind"] == "assembly"), None)
    if chosen is None:
        return modes
    size = sc.mechanism.size()
    same = lambda md: all(max(abs(a - b) for a, b in zip(md.points[pt], xy)) <= 1e-6 * size
                          for pt, xy in chosen["guess"].items())
    modes[:] = [replace(md, from_guess=same(md)) for md in modes]  # in place: a certified list stays one
    return modes


def _write_scenes(path, directory, modes) -> list[Path]:
    """DIR/<scene>_mode<k>.toml for every mode: the scene as written, with that mode's guess."""
    from ..views.atomic import open_replacing
    src, out = Path(path), Path(directory)
    text = src.read_text(encoding="utf-8")
    written = []
    target = out
    try:
        out.mkdir(parents=True, exist_ok=True)
        for k, md in enumerate(modes, 1):
            target = out / f"{src.stem}_mode{k}.toml"
            note = f"assembly mode {k} of {len(modes)}, found by `kincas modes {src.name}`"
            with open_replacing(target, "w", encoding="utf-8") as f:  # whole or not at all
                f.write(scene_with_guess(text, md, note))
            written.append(target)
    except OSError as e:
        raise OutputError(f"--write: cannot write {str(target)!r}: {e.strerror or e}") from None
    return written
