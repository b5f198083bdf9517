"""`kincas cam SCENE.toml`: design a disc cam from the scene's `[cam_design]` section.

Prints a summary (largest pressure angle, smallest radius of curvature, largest jerk
d3s/dtheta3, undercut), or with `--json` one JSON object (the follower's s and its first three
derivatives per cam angle, pressure angle, radii of curvature, undercut, the profile in polar
form and as x, y in the cam's frame); `--out PROFILE.toml` writes a scene-ready `[[cams]]` block with the
polar profile, `--csv OUT.csv` a row per cam angle. Angles in the scene's unit.

>>> import tempfile, pathlib
>>> d = pathlib.Path(tempfile.mkdtemp())
>>> _ = (d / "c.toml").write_text('''
... [cam_design]
... base_radius = 40
... segments = [{ motion = "rise", angle = 180, lift = 10, law = "harmonic" },
...             { motion = "return", angle = 180, lift = 10, law = "harmonic" }]
... ''')
>>> from kincas.cli import main
>>> main(["cam", str(d / "c.toml"), "--out", str(d / "p.toml")])  # doctest: +ELLIPSIS
cam design: 720 angles, ...
0
"""
from __future__ import annotations

import csv
import json
import math
import tomllib
from pathlib import Path

import numpy as np

from ..errors import OutputError, SceneError
from ..views.atomic import open_replacing
from ..synthesis.cam_design import Segment, design_cam

FIELDS = {"base_radius", "roller_radius", "offset", "samples", "segments", "name", "body", "follower"}


def cli_arguments(p):
    p.add_argument("scene", help="the scene file (TOML) with a [cam_design] section")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    p.add_argument("--out", metavar="PROFILE.toml", help="write a scene-ready [[cams]] block")
    p.add_argument("--csv", metavar="OUT.csv", help="write a row per cam angle")


def read(doc: dict):
    """(design, options) from a parsed scene; SceneError naming the field when wrong."""
    units = doc.get("units", {}) if isinstance(doc.get("units", {}), dict) else {}
    deg = units.get("angle", "deg") != "rad"
    t = doc.get("cam_design")
    if not isinstance(t, dict):
        raise SceneError("[cam_design]: missing (kincas cam designs the cam it describes)")
    bad = [f"[cam_design] {k}: unknown field (expected one of {sorted(FIELDS)})" for k in t if k not in FIELDS]

    def number(key, default=None):
        v = t.get(key, default)
        if isinstance(v, bool) or not isinstance(v, (int, float)):
            bad.append(f"[cam_design] {key}: expected a number, got {v!r}")
            return math.nan
        return float(v)
    base, rho, e = number("base_radius"), number("roller_radius", 0.0), number("offset", 0.0)
    samples = t.get("samples", 720)
    segs = []
    raw = t.get("segments")
    if not isinstance(raw, list) or not all(isinstance(x, dict) for x in raw):
        bad.append("[cam_design] segments: expected a list of { motion, angle, lift, law } tables")
        raw = []
    for k, sg in enumerate(raw):
        extra = set(sg) - {"motion", "angle", "lift", "law"}
        if extra:
            bad.append(f"[cam_design] segments[{k}]: unknown field(s) {sorted(extra)}")
        vals = {}
        for key, default in (("angle", None), ("lift", 0.0)):
            v = sg.get(key, default)
            if isinstance(v, bool) or not isinstance(v, (int, float)):
                bad.append(f"[cam_design] segments[{k}].{key}: expected a number, got {v!r}")
                v = math.nan
            vals[key] = float(v)
        angle = vals["angle"] if deg else math.degrees(vals["angle"])
        segs.append(Segment(str(sg.get("motion", "")), angle, vals["lift"], str(sg.get("law", "cycloidal"))))
    if bad:
        raise SceneError(bad)
    try:
        design = design_cam(segs, base, rho, e, samples)
    except ValueError as err:
        raise SceneError(str(err).split("\n")) from None
    names = {k: str(t.get(k, d)) for k, d in (("name", "cam"), ("body", "cam"), ("follower", "F"))}
    return design, names, deg


def profile_toml(design, names: dict, deg: bool, source: str = "") -> str:
    """A `[[cams]]` block with the designed polar profile (angles in the scene's unit)."""
    phi, r = design.polar()
    ang = np.degrees(phi) if deg else phi
    follower = (f'roller = {{ center = "{names["follower"]}", radius = {design.roller_radius!r} }}'
                if design.roller_radius > 0 else f'follower = "{names["follower"]}"')
    fmt = lambda a: ", ".join(repr(float(x)) for x in a)  # noqa: E731
    return (f"# cam profile designed by `kincas cam{(' ' + source) if source else ''}`: base radius "
            f"{design.base_radius:g}, roller {design.roller_radius:g}, offset {design.offset:g};\n"
            f"# the follower translates along x = offset; the cam turns counter-clockwise about its "
            f"body's origin\n[[cams]]\nname = \"{names['name']}\"\nbody = \"{names['body']}\"\n{follower}\n"
            f"[cams.profile.polar]\nangles = [{fmt(ang)}]\nradii = [{fmt(r)}]\n")


def _user(v, deg):
    return np.degrees(v) if deg else np.asarray(v)


def cli_run(args) -> int:
    path = Path(args.scene)
    try:
        doc = tomllib.loads(path.read_text(encoding="utf-8"))
    except OSError as e:
        raise SceneError(f"scene: cannot read {str(path)!r}: {e.strerror or e}") from None
    except tomllib.TOMLDecodeError as e:
        raise SceneError(f"scene: not valid TOML: {e}") from None
    d, names, deg = read(doc)
    unit = "deg" if deg else "rad"
    if args.out:
        try:
            with open_replacing(args.out, "w", encoding="utf-8") as f:  # whole or not at all
                f.write(profile_toml(d, names, deg, path.name))
        except OSError as e:
            raise OutputError(f"--out: cannot write {args.out!r}: {e.strerror or e}") from None
    per = float(_user(1.0, deg))  # scene units of angle per radian: d^k s/dtheta^k / per^k
    if args.csv:
        phi = np.arctan2(d.profile[:, 1], d.profile[:, 0])
        cols = {f"theta [{unit}]": _user(d.theta, deg), "s": d.s, f"ds/dtheta [per {unit}]": d.ds / per,
                f"d2s/dtheta2 [per {unit}^2]": d.dds / per ** 2, f"d3s/dtheta3 [per {unit}^3]": d.ddds / per ** 3,
                f"pressure [{unit}]": _user(d.pressure, deg),
                "rho_pitch": d.rho_pitch, "rho_profile": d.rho_profile, "undercut": d.undercut.astype(int),
                "profile_x": d.profile[:, 0], "profile_y": d.profile[:, 1],
                f"profile_angle [{unit}]": _user(phi, deg), "profile_radius": np.hypot(*d.profile.T)}
        try:
            with open_replacing(args.csv, "w", newline="", encoding="utf-8") as f:
                w = csv.writer(f)
                w.writerow(cols)
                w.writerows(zip(*[np.asarray(v).tolist() for v in cols.values()]))
        except OSError as e:
            raise OutputError(f"--csv: cannot write {args.csv!r}: {e.strerror or e}") from None
    k = int(np.argmax(d.pressure))
    convex = np.isfinite(d.rho_profile)
    j = int(np.argmin(np.where(convex, np.abs(d.rho_profile), np.inf)))
    if args.json:
        fin = lambda a: [None if not math.isfinite(x) else x for x in np.asarray(a, float).tolist()]  # noqa: E731
        phi, r = d.polar()
        units = {"angle": unit, "ds/dtheta": f"length/{unit}", "d2s/dtheta2": f"length/{unit}^2",
                 "d3s/dtheta3": f"length/{unit}^3"}
        print(json.dumps({"units": units, "theta": fin(_user(d.theta, deg)), "s": fin(d.s),
                          "ds/dtheta": fin(d.ds / per), "d2s/dtheta2": fin(d.dds / per ** 2),
                          "d3s/dtheta3": fin(d.ddds / per ** 3),
                          "pressure": fin(_user(d.pressure, deg)), "rho_pitch": fin(d.rho_pitch),
                          "rho_profile": fin(d.rho_profile), "undercut": d.undercut.tolist(),
                          "profile": {"angles": fin(_user(phi, deg)), "radii": fin(r),
                                      "x": fin(d.profile[:, 0]), "y": fin(d.profile[:, 1])}}))
    else:
        print(f"cam design: {len(d.theta)} angles, largest pressure angle "
              f"{float(_user(d.pressure[k], deg)):.4g} {unit} at {float(_user(d.theta[k], deg)):.4g} {unit}, "
              f"smallest |radius of curvature| of the profile {abs(d.rho_profile[j]):.4g} "
              f"at {float(_user(d.theta[j], deg)):.4g} {unit}")
        i = int(np.argmax(np.abs(d.ddds)))  # the follower's jerk, per cam angle cubed
        print(f"largest |d3s/dtheta3| {abs(d.ddds[i]) / per ** 3:.6g} per {unit}^3 "
              f"at {float(_user(d.theta[i], deg)):.4g} {unit} (the jerk is this times the cam's speed cubed)")
        if d.undercut.any():
            a = _user(d.theta[d.undercut], deg)
            print(f"undercut: the roller cannot follow the profile from {a.min():.4g} to {a.max():.4g} {unit}")
    return 0
