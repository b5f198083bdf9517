"""A flat-faced follower touches a cam only where the profile is convex (issue 14, item 4).

The face's equations (kincas/core/joints.py: the face through the profile point P, along
its tangent T) hold at every point where the tangent is parallel to the face, supporting or
not. On a convex profile every tangent line is a supporting line: the whole cam is on one
side of the face. On a profile with a concave part, a tangent line there cuts the cam, and
the contact jumps across the concavity: such a profile is refused for a flat follower (as a
roller too large for the concave parts is), and a convex one keeps the cam on its side.

Independent check: the profile rebuilt by scipy's periodic cubic spline through the same
points; the face of a translating tappet is the cam's support line, at the height
h(theta) = max over phi of r(phi) sin(phi + theta)."""
from __future__ import annotations

import numpy as np
import pytest
from scipy.interpolate import CubicSpline
from scipy.optimize import minimize_scalar

import kincas
from conftest import run_cli, write_scene
from kincas import Input, Link, Mechanism, Slide
from kincas.errors import ModelError
from kincas.model import Cam, Polar

STEP = 10.0  # degrees between the profile's points


def profile(a):
    """r = 30 (1 + a cos 2 phi) at every STEP degrees: convex everywhere for a = 0.05,
    concave about phi = 90 and 270 deg for a = 0.3 (r^2 + 2 r'^2 - r r'' = 900 (0.49 - 0.84)
    there)."""
    ang = np.radians(np.arange(0, 360, STEP))
    return ang, 30 * (1 + a * np.cos(2 * ang))


def tappet(a) -> Mechanism:
    """A tappet translating along x = 0 (its face: its x axis, through F) on the cam."""
    ang, radii = profile(a)
    return Mechanism(
        ground={"O": (0, 0)},
        links=[Link("cam", {"O": (0, 0), "K": (10, 0)}), Link("tappet", {"F": (0, 0), "S": (0, 50)})],
        slides=[Slide("F", "ground", through=(0, 0), angle=np.pi / 2, name="g1"),
                Slide("S", "ground", through=(0, 0), angle=np.pi / 2, name="g2")],
        cams=[Cam("cam", "cam", Polar(ang, radii.tolist()), flat="tappet")],
        inputs=[Input.angle("cam")], guess={"F": (0, 40), "S": (0, 90)})


def scipy_profile(a):
    ang, radii = profile(a)
    return CubicSpline(np.append(ang, 2 * np.pi), np.append(radii, radii[0]), bc_type="periodic")


def test_concave_profile_is_refused_for_a_flat_face():
    with pytest.raises(ModelError, match=r"\[\[cams\]\] cam: flat: .*not convex") as e:
        tappet(0.3)
    # the message says where: at phi = 90 deg (or 270), r = 30 (1 - 0.3) = 21, a knot
    assert "most concave at (0, 21)" in str(e.value) or "most concave at (0, -21)" in str(e.value)


def test_the_concave_test_is_the_polar_curvature_sign():
    """Right at the edge: r = 30 (1 + a cos 2 phi) is convex everywhere while
    r^2 + 2 r'^2 - r r'' > 0, i.e. (at phi = 90 deg, the worst) 1 - a > 4 a: a < 1/5.
    The spline through points every 10 degrees is within a small fraction of that."""
    for a in (0.17, 0.18):
        tappet(a)
    for a in (0.22, 0.25):
        with pytest.raises(ModelError, match="flat"):
            tappet(a)


def test_convex_profile_keeps_the_cam_under_the_face():
    m = tappet(0.05)
    th = np.radians(np.arange(0, 361, 5.0))
    sw = kincas.sweep(m, {"cam.angle": th}, report=["F.x", "F.y", "tappet.angle",
                                                    "cam.contact.x", "cam.contact.y"])
    assert sw.status.tolist() == ["ok"] * len(th) and sw.residual.max() < 1e-12
    r = scipy_profile(0.05)
    phi = np.linspace(0, 2 * np.pi, 7200, endpoint=False)
    for k, t in enumerate(th):
        X, Y = r(phi) * np.cos(phi + t), r(phi) * np.sin(phi + t)
        d = np.array([np.cos(sw["tappet.angle"][k]), np.sin(sw["tappet.angle"][k])])
        side = d[0] * (Y - sw["F.y"][k]) - d[1] * (X - sw["F.x"][k])  # > 0: above the face
        assert side.max() < 1e-9, (np.degrees(t), side.max())
        # the face is the support line: its height is the profile's highest point
        j = int(np.argmax(Y))
        h = phi[1]  # r is periodic (extrapolated so): no wrapping at the seam
        best = minimize_scalar(lambda p: -r(p) * np.sin(p + t), bounds=(phi[j] - h, phi[j] + h),
                               method="bounded", options={"xatol": 1e-10})
        assert sw["F.y"][k] == pytest.approx(-best.fun, abs=1e-9)
        assert sw["cam.contact.y"][k] == pytest.approx(-best.fun, abs=1e-9)


def scene(a) -> dict:
    ang, radii = profile(a)
    return {"title": "flat tappet on a polar cam", "units": {"length": "mm", "angle": "deg", "time": "s"},
            "ground": {"O": [0, 0]},
            "links": {"cam": {"points": {"O": [0, 0], "K": [10, 0]}},
                      "tappet": {"points": {"F": [0, 0], "S": [0, 50]}}},
            "slides": [{"name": "g1", "point": "F", "along": "ground", "line": {"through": [0, 0], "angle": 90}},
                       {"name": "g2", "point": "S", "along": "ground", "line": {"through": [0, 0], "angle": 90}}],
            "cams": [{"name": "cam", "body": "cam", "flat": "tappet",
                      "profile": {"polar": {"angles": np.degrees(ang).tolist(), "radii": radii.tolist()}}}],
            "inputs": [{"angle": "cam", "sweep": {"from": 0, "to": 360, "steps": 73}}],
            "guess": {"F": [0, 40], "S": [0, 90]}, "output": {"report": ["F.y"]}}


def test_scene_with_a_concave_profile_exits_2_naming_the_cam_and_field(capsys, tmp_path):
    code, _, err = run_cli(capsys, "solve", write_scene(tmp_path, scene(0.3)), "--json")
    assert code == 2 and "Traceback" not in err
    assert "[[cams]] cam" in err and "flat" in err and "convex" in err
    code, out, err = run_cli(capsys, "solve", write_scene(tmp_path, scene(0.05)), "--json")
    assert code == 0 and out["status"] == ["ok"] * 73, err
