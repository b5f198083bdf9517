"""`kincas solve SCENE --json` on the examples, checked against independent closed forms.

The closed forms (tests/closed_forms.py) read their dimensions from the same TOML files.
Velocities and accelerations are checked against central differences of the closed-form
positions, so nothing here trusts kincas's own derivatives. The first tests check the closed
forms and the example files themselves and need no kincas.
"""
from __future__ import annotations

import copy
import math
import tomllib

import numpy as np
import pytest

import closed_forms as cf
from conftest import EXAMPLES, dump_toml, run_cli, write_scene

KINDS = list(cf.CLOSED_FORMS)  # one closed form per example, named as the file
# spatial scenes (space = "3d") have their own closed forms: tests/test_space_examples.py
SHIPPED = sorted(p for p in EXAMPLES.glob("*.toml") if not p.stem.startswith(("space_", "simulate_space_")))

POSITION_TOL = 1e-9  # relative to the size of the mechanism
ANGLE_TOL_RAD = 1e-9  # the same as an angle: a link of size L turned by 1e-9 rad moves by 1e-9 L
RATE_TOL = 1e-7  # velocities and accelerations, relative to the largest of their kind

RATE_NAMES = {"x": ("vx", "ax"), "y": ("vy", "ay"), "angle": ("omega", "alpha"), "s": ("v", "a")}
RATE_GROUPS = {"vx": "v", "vy": "v", "v": "v", "omega": "omega",
               "ax": "a", "ay": "a", "a": "a", "alpha": "alpha"}


# ----------------------------------------------------------------------------- helpers

def derived(name: str, order: int) -> str:
    """The name of the velocity (order 1) or acceleration (2) of a position quantity."""
    obj, q = name.rsplit(".", 1)
    return f"{obj}.{RATE_NAMES[q][order - 1]}"


def full_report(scene: dict, kind: str) -> list[str]:
    """Every quantity the closed form knows, with its velocity and acceleration."""
    names = cf.solve(kind, scene, cf.input_values(scene)[:1]).quantities()
    return [n for name in names for n in (name, derived(name, 1), derived(name, 2))]


def with_report(scene: dict, kind: str) -> dict:
    return {**scene, "output": {"report": full_report(scene, kind)}}


def with_input(scene: dict, **changes) -> dict:
    """A copy of the scene whose (single) input has `changes` (None removes a key)."""
    spec = {**scene["inputs"][0], **changes}
    if "value" in changes:
        spec.pop("sweep", None)
    if "sweep" in changes:
        spec.pop("value", None)
    return {**scene, "inputs": [{k: v for k, v in spec.items() if v is not None}]}


def input_rates(scene: dict) -> tuple[float, float]:
    spec = scene["inputs"][0]
    return cf.num(scene, spec.get("rate", 1)), cf.num(scene, spec.get("acceleration", 0))


def size_of(sol: cf.Solution) -> float:
    """The mechanism's size: its largest coordinate over the poses."""
    return float(np.nanmax(np.abs(np.concatenate(list(sol.points.values())))))


def step_for(scene: dict, size: float) -> float:
    """Difference step in the input's unit: 1e-3 rad for an angle, 1e-4 of the size else."""
    kind, _ = cf.input_kind(scene)
    return 1e-3 / cf.angle_unit(scene) if kind == "angle" else 1e-4 * size


def closed_form_rates(kind: str, scene: dict, u, h: float) -> dict[str, np.ndarray]:
    """Velocities and accelerations from 5-point central differences of the closed form:
    P.v = dP/du * rate, P.a = d2P/du2 * rate**2 + dP/du * acceleration."""
    rate, acc = input_rates(scene)
    half_turn = math.pi / cf.angle_unit(scene)
    f = [cf.solve(kind, scene, u + j * h).quantities() for j in (-2, -1, 0, 1, 2)]
    out = {}
    for name in f[2]:
        g = [q[name] for q in f]
        if name.endswith(".angle"):  # unwrap around the middle sample
            g = [g[2] + cf.wrap(gj - g[2], half_turn) for gj in g]
        d1 = (g[0] - 8 * g[1] + 8 * g[3] - g[4]) / (12 * h)
        d2 = (-g[0] + 16 * g[1] - 30 * g[2] + 16 * g[3] - g[4]) / (12 * h * h)
        out[derived(name, 1)] = d1 * rate
        out[derived(name, 2)] = d2 * rate**2 + d1 * acc
    return out


def values(out: dict, name: str) -> np.ndarray:
    assert name in out["values"], f"{name} missing from values: {sorted(out['values'])}"
    return np.array(out["values"][name], dtype=float)  # null -> NaN


def assert_positions(out, expected: dict, scene: dict, size: float, poses=slice(None)):
    """Positions and slide coordinates to 1e-9 of the size, angles to 1e-9 rad (wrapped)."""
    k = cf.angle_unit(scene)
    for name, exp in expected.items():
        got = values(out, name)[poses]
        exp = exp[poses]
        if name.endswith(".angle"):
            half_turn = math.pi / k
            solved = got[np.isfinite(got)]
            assert np.all((solved > -half_turn) & (solved <= half_turn)), f"{name} is not wrapped"
            err, tol = np.abs(cf.wrap(got - exp, half_turn)), ANGLE_TOL_RAD / k
        else:
            err, tol = np.abs(got - exp), POSITION_TOL * size
        assert np.all(err <= tol), (
            f"{name}: error {np.nanmax(err):.3g} > {tol:.3g} at pose {int(np.nanargmax(err))}"
            f" (or NaN: {int(np.isnan(err).sum())})")


def assert_rates(out, expected: dict):
    """Velocities and accelerations to RATE_TOL of the largest of their kind."""
    scale = {}
    for name, exp in expected.items():
        group = RATE_GROUPS[name.rsplit(".", 1)[1]]
        scale[group] = max(scale.get(group, 0.0), float(np.nanmax(np.abs(exp))))
    for name, exp in expected.items():
        tol = RATE_TOL * scale[RATE_GROUPS[name.rsplit(".", 1)[1]]]
        err = np.abs(values(out, name) - exp)
        assert np.all(err <= tol), (
            f"{name}: error {np.nanmax(err):.3g} > {tol:.3g} at pose {int(np.nanargmax(err))}"
            f" (or NaN: {int(np.isnan(err).sum())})")


def solve_cli(capsys, tmp_path, scene: dict):
    return run_cli(capsys, "solve", write_scene(tmp_path, scene), "--json")


def check_against_closed_form(out, scene: dict, kind: str):
    u = cf.input_values(scene)
    assert list(out["inputs"]) == [cf.input_key(scene)]
    np.testing.assert_allclose(out["inputs"][cf.input_key(scene)], u, rtol=1e-12, atol=1e-12)
    assert out["status"] == ["ok"] * len(u)
    sol = cf.solve(kind, scene, u)
    size = size_of(sol)
    assert_positions(out, sol.quantities(), scene, size)
    assert_rates(out, closed_form_rates(kind, scene, u, step_for(scene, size)))


def mobility(scene: dict) -> int:
    """Degrees of freedom by counting: 3 per link, less 2 per revolute (a point held by m bodies,
    the ground counting as one, is m - 1 revolutes), less 1 per slide, gear pair, rack or cam; plus 1 per driven
    parameter (a link whose length is driven is not rigid)."""
    holders: dict[str, int] = {name: 1 for name in scene.get("ground", {})}
    for link in scene["links"].values():
        for p in link["points"]:
            holders[p] = holders.get(p, 0) + 1
    dof = 3 * len(scene["links"]) - sum(2 * (m - 1) for m in holders.values())
    dof -= len(scene.get("slides", []))
    dof -= len(scene.get("gears", [])) + len(scene.get("racks", [])) + len(scene.get("cams", []))
    return dof + sum("parameter" in spec for spec in scene["inputs"])


# ----------------------------------------------------------------------------- the closed forms
# and the example files, without kincas

# Checked by other files: chains no dyad method solves (tests/test_class3.py) and
# optimisation studies (tests/test_optimize.py); forces and geometry (tests/test_forces_examples.py).
NO_CLOSED_FORM = {"assur_triad", "stephenson3", "eightbar"}
# Gears, racks, cams, relative inputs, fixed pins in moving slots: tests/test_joint_examples.py
JOINT_EXAMPLES = {"designed_cam", "geared_fivebar", "planetary", "rack_fourbar", "eccentric_cam", "roller_cam",
                  "flat_tappet", "elbow_arm", "whitworth"}


def _checked_elsewhere(stem: str) -> bool:
    return stem in NO_CLOSED_FORM or stem in JOINT_EXAMPLES or stem.startswith(
        ("synthesis_", "optimize_", "forces_", "simulate_"))  # simulate_: tests/test_simulate.py


def test_every_example_has_a_closed_form():
    assert sorted(p.stem for p in SHIPPED if not _checked_elsewhere(p.stem)) == sorted(KINDS)


@pytest.mark.parametrize("path", SHIPPED, ids=lambda p: p.stem)
def test_example_file_is_well_formed(path):
    text = path.read_text(encoding="utf-8")
    assert text.startswith("#"), "each example opens with a comment saying what it is"
    scene = tomllib.loads(text)
    units = dict(scene["units"])
    labels = {k: units.pop(k) for k in ("force", "mass") if k in units}  # labels only (format v3)
    assert units == {"length": "mm", "angle": "deg", "time": "s"}
    assert labels in ({}, {"force": "N"}, {"force": "N", "mass": "t"})  # N with mm, s: masses in t
    assert scene["guess"] and scene["output"]["report"]
    assert len(scene["inputs"]) == mobility(scene) == (2 if path.stem == "elbow_arm" else 1)
    assert tomllib.loads(dump_toml(scene)) == scene  # the tests' scene writer round-trips it


@pytest.mark.parametrize("kind", KINDS)
def test_closed_form_satisfies_the_scene(kind):
    """Over the whole sweep: every constraint of the scene holds, the mechanism assembles,
    and the chosen branch's first pose is the one the guess points at."""
    scene = cf.load_scene(kind)
    sol = cf.solve(kind, scene)
    size = size_of(sol)
    assert np.all(sol.residuals() < 1e-12 * size)
    assert all(np.all(np.isfinite(v)) for v in sol.quantities().values())
    for name, xy in scene["guess"].items():
        assert np.linalg.norm(sol.points[name][0] - cf.vec(scene, xy)) < 0.01 * size, name


def assert_fairbairn_textbook_values(q: dict):
    """The textbook's answer at crank angle 130 deg, to its rounding."""
    assert round(q["D.x"], 1) == 246.4 and round(q["D.y"], 1) == 99.6
    assert round(q["lever.angle"], 1) == 22.0
    # A-D is 265.798 mm: the textbook's 265.7 is one unit off in its last digit
    assert abs(q["slot.s"] - 265.7) < 0.1
    assert round(q["E.x"]) == 510 and round(q["E.y"]) == 206
    assert round(q["rod.angle"], 1) == -58.1
    assert round(q["F.y"]) == -100 and q["F.x"] == pytest.approx(700, abs=1e-9)
    assert q["guide.s"] == pytest.approx(q["F.y"], abs=1e-9)


def test_fairbairn_closed_form_gives_the_textbook_values():
    sol = cf.solve("fairbairn", cf.load_scene("fairbairn"), [130.0])
    assert_fairbairn_textbook_values({k: v[0] for k, v in sol.quantities().items()})


def _hand(r, l, e, th):
    """Offset slider-crank by the textbook formula: x = r cos th + sqrt(l^2 - (e - r sin th)^2)."""
    return r * math.cos(th) + math.sqrt(l * l - (e - r * math.sin(th)) ** 2)


HAND_NUMBERS = [
    # kind, input, quantity, value worked out by hand (triangle by triangle)
    ("slider_crank", 0, "B.x", 50 + math.sqrt(180**2 - 20**2)),
    ("slider_crank", 90, "B.x", math.sqrt(180**2 - 30**2)),
    ("slider_crank", 180, "B.x", -50 + math.sqrt(180**2 - 20**2)),
    ("slider_crank", 250, "slider.s", _hand(50, 180, 20, math.radians(250))),
    ("slider_crank", 90, "rod.angle", -math.degrees(math.asin(30 / 180))),
    # four-bar at 0: A = (30, 0), A-O4 = 70; B from the triangle 90, 80, 70
    ("fourbar_coupler", 0, "B.x", 30 + (70**2 + 90**2 - 80**2) / 140),
    ("fourbar_coupler", 0, "B.y", math.sqrt(90**2 - ((70**2 + 90**2 - 80**2) / 140) ** 2)),
    # four-bar at 180: A = (-30, 0), A-O4 = 130
    ("fourbar_coupler", 180, "B.x", -30 + (130**2 + 90**2 - 80**2) / 260),
    # V-twin at 0: C = (40, 0), 28.28 along and 28.28 across each cylinder
    ("vtwin", 0, "front.s", 40 * math.sqrt(0.5) + math.sqrt(140**2 - 800)),
    ("vtwin", 0, "rear.s", -40 * math.sqrt(0.5) + math.sqrt(140**2 - 800)),
    ("vtwin", 90, "front.s", 40 * math.sqrt(0.5) + math.sqrt(140**2 - 800)),
    ("vtwin", 90, "rear.s", 40 * math.sqrt(0.5) + math.sqrt(140**2 - 800)),
    ("vtwin", 180, "front.s", -40 * math.sqrt(0.5) + math.sqrt(140**2 - 800)),
    # six-bar at 0: A = (25, 0), A-O4 = 55; B from the triangle 90, 60, 55
    ("sixbar", 0, "B.x", 25 + (55**2 + 90**2 - 60**2) / 110),
    ("sixbar", 0, "rocker.angle",
     math.degrees(math.atan2(math.sqrt(90**2 - ((55**2 + 90**2 - 60**2) / 110) ** 2),
                             25 + (55**2 + 90**2 - 60**2) / 110 - 80))),
    # actuator 230: G = (-250, 0), O = (0, 0): P from the triangle 230, 60, 250
    ("actuator_bellcrank", 230, "P.x", -250 + (250**2 + 230**2 - 60**2) / 500),
    ("actuator_bellcrank", 230, "P.y", math.sqrt(230**2 - ((250**2 + 230**2 - 60**2) / 500) ** 2)),
    # actuator sqrt(250^2 + 60^2): P = (0, 60), Q = (80, 0), Q-O5 = 140: R from 150, 80, 140
    ("actuator_bellcrank", math.hypot(250, 60), "bellcrank.angle", 90.0),
    ("actuator_bellcrank", math.hypot(250, 60), "R.x", 80 + (140**2 + 150**2 - 80**2) / 280),
    ("actuator_bellcrank", math.hypot(250, 60), "R.y", math.sqrt(150**2 - 127.5**2)),
]


@pytest.mark.parametrize("kind,u,name,expected", HAND_NUMBERS)
def test_closed_form_hand_numbers(kind, u, name, expected):
    got = cf.solve(kind, cf.load_scene(kind), [u]).quantities()[name][0]
    assert got == pytest.approx(expected, rel=1e-12, abs=1e-12)


def test_sixbar_slider_position_by_hand():
    """C from the rocker's angle and the arm (-60, 35); D 160 mm from C on y = -60."""
    scene = cf.load_scene("sixbar")
    q = cf.solve("sixbar", scene, [0.0]).quantities()
    phi = math.radians(q["rocker.angle"][0])
    cx = 80 - 60 * math.cos(phi) - 35 * math.sin(phi)
    cy = -60 * math.sin(phi) + 35 * math.cos(phi)
    assert q["C.x"][0] == pytest.approx(cx, rel=1e-12)
    assert q["D.x"][0] == pytest.approx(cx + math.sqrt(160**2 - (cy + 60) ** 2), rel=1e-12)


def test_closed_form_differences_match_exact_derivatives():
    """The differences used for velocities and accelerations, checked on the slider-crank's
    exact derivative of x(th) = r cos th + sqrt(l^2 - (e - r sin th)^2)."""
    r, l, e = 50.0, 180.0, 20.0
    scene = with_input(cf.load_scene("slider_crank"), rate=2.0, acceleration=3.0)
    u = cf.input_values(scene)
    th = np.radians(u)
    w = e - r * np.sin(th)
    root = np.sqrt(l * l - w * w)
    dx = -r * np.sin(th) + w * r * np.cos(th) / root  # per radian
    ddx = -r * np.cos(th) + (-(r * np.cos(th)) ** 2 - w * r * np.sin(th)) / root \
        - (w * r * np.cos(th)) ** 2 / root**3
    k = math.pi / 180
    rates = closed_form_rates("slider_crank", scene, u, step_for(scene, 230.0))
    np.testing.assert_allclose(rates["B.vx"], dx * k * 2, rtol=0, atol=1e-10 * np.abs(dx * k * 2).max())
    exact_a = ddx * k * k * 4 + dx * k * 3
    np.testing.assert_allclose(rates["B.ax"], exact_a, rtol=0, atol=1e-8 * np.abs(exact_a).max())


# ----------------------------------------------------------------------------- kincas's CLI

@pytest.mark.parametrize("kind", KINDS)
def test_example_matches_closed_form(capsys, tmp_path, kind):
    """The example's own sweep, rate and acceleration, every quantity reported."""
    scene = with_report(cf.load_scene(kind), kind)
    code, out, err = solve_cli(capsys, tmp_path, scene)
    assert code == 0, err
    check_against_closed_form(out, scene, kind)


@pytest.mark.parametrize("kind", KINDS)
def test_rate_and_acceleration(capsys, tmp_path, kind):
    """rate = 2, acceleration = 3: P.v = dP/du * 2 and P.a = d2P/du2 * 4 + dP/du * 3."""
    scene = cf.load_scene(kind)
    sweep = scene["inputs"][0]["sweep"]
    scene = with_input(scene, rate=2, acceleration=3,
                       sweep={**sweep, "steps": (sweep["steps"] - 1) // 2 + 1})
    scene = with_report(scene, kind)
    code, out, err = solve_cli(capsys, tmp_path, scene)
    assert code == 0, err
    check_against_closed_form(out, scene, kind)
    if cf.input_kind(scene)[0] == "angle":  # the driven link turns at exactly the input's rates
        np.testing.assert_allclose(values(out, "crank.omega"), 2, rtol=1e-12)
        np.testing.assert_allclose(values(out, "crank.alpha"), 3, rtol=1e-12)


def test_fairbairn_textbook_pose(capsys, tmp_path):
    """The textbook's answer at crank angle 130 deg, a single pose (`value = 130`)."""
    scene = with_report(with_input(cf.load_scene("fairbairn"), value=130), "fairbairn")
    code, out, err = solve_cli(capsys, tmp_path, scene)
    assert code == 0, err
    assert out["status"] == ["ok"] and len(out["flags"]) == 1
    assert_fairbairn_textbook_values({name: v[0] for name, v in out["values"].items()})
    check_against_closed_form(out, scene, "fairbairn")  # inputs == [130], 1e-9 agreement


def scaled(scene: dict, s: float) -> dict:
    """The same mechanism with every length times s (all its parameters are lengths)."""
    def xy(p):
        return [v * s if not isinstance(v, str) else v for v in p]
    out = copy.deepcopy(scene)
    out["parameters"] = {k: v * s for k, v in scene["parameters"].items()}
    out["ground"] = {k: xy(p) for k, p in scene["ground"].items()}
    out["guess"] = {k: xy(p) for k, p in scene["guess"].items()}
    for link in out["links"].values():
        if isinstance(link["points"], dict):
            link["points"] = {k: xy(p) for k, p in link["points"].items()}
        if not isinstance(link.get("length", ""), str):
            link["length"] *= s
    return out


def test_scale_invariance(capsys, tmp_path):
    """The four-bar at scales 1e-6, 1, 1e6: the same angles to 1e-9 deg, positions to 1e-9."""
    base = cf.load_scene("fourbar_coupler")
    base = with_input(base, sweep={"from": 0, "to": 360, "steps": 25})
    results = {}
    for s in (1e-6, 1.0, 1e6):
        scene = with_report(scaled(base, s), "fourbar_coupler")
        code, out, err = solve_cli(capsys, tmp_path, scene)
        assert code == 0, f"scale {s}: {err}"
        check_against_closed_form(out, scene, "fourbar_coupler")
        results[s] = out["values"]
    for s in (1e-6, 1e6):
        for name, ref in results[1.0].items():
            got, ref = np.array(results[s][name], dtype=float), np.array(ref, dtype=float)
            kind = name.rsplit(".", 1)[1]
            if kind == "angle":
                assert np.all(np.abs(cf.wrap(got - ref)) <= 1e-9), (s, name)
            elif kind in ("omega", "alpha"):
                assert np.all(np.abs(got - ref) <= 1e-9 * np.abs(ref).max()), (s, name)
            else:
                assert np.all(np.abs(got / s - ref) <= 1e-9 * np.abs(ref).max()), (s, name)


def _slide_driven_slider_crank():
    """The slider-crank driven by the slider's position, from 150 mm past the rod's reach
    (sqrt(230^2 - 20^2) = 229.13 mm), every 10 mm; the crank above the line O-B."""
    scene = cf.load_scene("slider_crank")
    scene = {**scene, "guess": {"A": [20, 46], "B": [150, 20]}}
    return with_input(scene, angle=None, slide="slider",
                      sweep={"from": 150, "to": 260, "steps": 12}), "slider_crank", 8


def _overstroked_actuator():
    """The actuator pushed from 260 to 340 mm; the four-bar stops assembling at 309.93 mm."""
    scene = cf.load_scene("actuator_bellcrank")
    return with_input(scene, sweep={"from": 260, "to": 340, "steps": 5}), "actuator_bellcrank", 3


@pytest.mark.parametrize("make", [_slide_driven_slider_crank, _overstroked_actuator],
                         ids=["slide-past-reach", "actuator-past-reach"])
def test_sweep_out_of_range(capsys, tmp_path, make):
    scene, kind, n_ok = make()
    scene = with_report(scene, kind)
    u = cf.input_values(scene)
    sol = cf.solve(kind, scene, u)
    q = sol.quantities()
    reachable = np.all([np.isfinite(v) for v in q.values()], axis=0)
    assert reachable.tolist() == [True] * n_ok + [False] * (len(u) - n_ok)  # the test's premise

    code, out, err = solve_cli(capsys, tmp_path, scene)
    assert code == 3, err
    n = len(u)
    assert len(out["status"]) == len(out["flags"]) == n
    assert out["status"][:n_ok] == ["ok"] * n_ok
    assert all(isinstance(st, str) and st and st != "ok" for st in out["status"][n_ok:])
    for name, v in out["values"].items():
        assert len(v) == n, name
        assert all(x is None for x in v[n_ok:]), f"{name} has numbers where no pose was solved"
        assert all(x is not None for x in v[:n_ok]), name
    ok = slice(0, n_ok)
    assert_positions(out, q, scene, size_of(sol), poses=ok)
    rates = closed_form_rates(kind, scene, u[ok], step_for(scene, size_of(sol)))
    assert_rates({"values": {k: v[ok] for k, v in out["values"].items()}}, rates)


@pytest.mark.parametrize("path", SHIPPED, ids=lambda p: p.stem)
def test_shipped_example_solves(capsys, path):
    """Every example as shipped: exit 0, the report's quantities, one entry per pose."""
    scene = cf.load_scene(path)
    code, out, err = run_cli(capsys, "solve", path, "--json")
    assert code == 0, err
    assert "Traceback" not in err
    n = len(cf.input_values(scene))
    assert out["title"] == scene["title"] and out["units"] == scene["units"]
    assert list(out["inputs"]) == [cf.input_key(scene, i) for i in range(len(scene["inputs"]))]
    assert all(len(v) == n for v in out["inputs"].values())
    assert out["status"] == ["ok"] * n
    assert len(out["flags"]) == n
    assert set(scene["output"]["report"]) <= set(out["values"])
    # a cam's pressure angle is null where the follower stands (the contract says so)
    assert all(len(v) == n and (None not in v or k.endswith(".pressure")) for k, v in out["values"].items())


def test_default_report_is_positions_and_angles(capsys, tmp_path):
    """Without [output]: positions of all moving points and angles of all links."""
    scene = {k: v for k, v in cf.load_scene("fourbar_coupler").items() if k != "output"}
    scene = with_input(scene, value=40)
    code, out, err = solve_cli(capsys, tmp_path, scene)
    assert code == 0, err
    expected = cf.solve("fourbar_coupler", scene).quantities()
    assert set(out["values"]) == set(expected)
    assert_positions(out, expected, scene, 130.0)
