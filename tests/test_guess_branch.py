"""Issue [14], items 6 and 8: the guessed points pick the branch; without a guess, an
assembly that runs the whole sweep.

Item 6: points that are not guessed are placed to agree with the guessed ones, so the branch
is the one nearest the guessed points (a slider-crank driven by its slide, only the crank pin
guessed; the quick-return mechanism with only the ram guessed). Item 8: with no [guess], the
Whitworth quick return runs all 73 poses on an assembly the sweep chose, and says so in an
event; with a guess, the guess is obeyed even where its branch fails poses.

Every answer is a closed form written here: circle and line intersections for positions, the
closure's derivative for the crank's angular velocity.
"""
from __future__ import annotations

import math
import tomllib

import numpy as np
import pytest

import kincas
import kincas.cli.scene
from conftest import EXAMPLES, dump_toml, run_cli, write_scene
from kincas import Input, Link, Mechanism, Slide
from kincas.analysis.modes import find_modes

# --- item 6: a slider-crank driven by its slide, only the crank pin guessed ---


def slide_driven(a, b, e):
    """Crank AB (length a) about the ground point A = (0, 0), rod BC (length b), C on the
    ground line y = e; the input is C's coordinate s = C.x along that line."""
    return Mechanism(ground={"A": (0, 0)}, links=[Link.bar("AB", "A", "B", a), Link.bar("BC", "B", "C", b)],
                     slides=[Slide("C", "ground", through=(0, e), name="guide")],
                     inputs=[Input.slide("guide")])


def crank_angles(a, b, e, x):
    """Both crank angles t with |B - C| = b, B = a (cos t, sin t), C = (x, e): the closure
    x cos t + e sin t = K, K = (a^2 + x^2 + e^2 - b^2) / (2a), so t = atan2(e, x) +- acos(K / R)."""
    K, R = (a * a + x * x + e * e - b * b) / (2 * a), math.hypot(x, e)
    base, half = math.atan2(e, x), math.acos(K / R)
    return base + half, base - half


def crank_omega(a, e, x, t):
    """dt/dx from the closure F(t, x) = x cos t + e sin t - K(x) = 0 (the slide's rate is 1):
    dt/dx = -F_x / F_t, F_x = cos t - x / a, F_t = -x sin t + e cos t."""
    return -(math.cos(t) - x / a) / (-x * math.sin(t) + e * math.cos(t))


def wrapped(a):
    return (a + math.pi) % (2 * math.pi) - math.pi


# (a, b, e, x): the first six gave the mirror assembly before the fix
SLIDE_CASES = [(1.0, 1.780, 0.450, 0.662), (1.0, 1.258, -0.047, -1.711), (1.0, 0.902, 0.470, 0.172),
               (1.0, 2.114, 0.220, -2.528), (1.0, 2.083, -0.120, -1.609), (1.0, 1.210, -0.186, -0.573),
               (1.0, 2.0, 0.0, 2.0), (1.0, 1.5, 0.3, 1.2)]


@pytest.mark.parametrize("a, b, e, x", SLIDE_CASES)
@pytest.mark.parametrize("which", [0, 1])
def test_the_guessed_crank_pin_picks_the_branch(a, b, e, x, which):
    m = slide_driven(a, b, e)
    t = crank_angles(a, b, e, x)[which]
    B = np.array([a * math.cos(t), a * math.sin(t)])
    guess = {"B": tuple(B + 1e-3)}  # only B, 1e-3 from the wanted pose
    sw = kincas.sweep(m, {"guide.s": [x]}, guess=guess, report=["AB.angle", "AB.omega", "B.x", "B.y", "C.x"])
    assert sw.ok.all()
    assert abs(wrapped(sw["AB.angle"][0] - t)) <= 1e-12
    assert sw["AB.omega"][0] == pytest.approx(crank_omega(a, e, x, t), rel=1e-9)
    assert math.hypot(sw["B.x"][0] - sw["C.x"][0], sw["B.y"][0] - e) == pytest.approx(b, rel=1e-12)
    # the careful path takes the same assembly
    careful = kincas.sweep(m, {"guide.s": [x]}, guess=guess, report=["AB.angle"], method="careful")
    assert abs(wrapped(careful["AB.angle"][0] - t)) <= 1e-12


@pytest.mark.parametrize("a, b, e, x", SLIDE_CASES[:3])
def test_modes_marks_the_mode_the_guess_gives(a, b, e, x):
    for t in crank_angles(a, b, e, x):
        B = (a * math.cos(t) + 1e-3, a * math.sin(t) + 1e-3)
        m = slide_driven(a, b, e)
        m = Mechanism(ground=m.ground, links=m.links, slides=m.slides, inputs=m.inputs, guess={"B": B})
        modes = find_modes(m, {"guide.s": x}, starts=64)
        assert len(modes) == 2
        marked = [md for md in modes if md.from_guess]
        assert len(marked) == 1
        assert abs(wrapped(marked[0].angles["AB"] - t)) <= 1e-9


def test_cli_modes_marks_the_mode_the_guess_gives(capsys, tmp_path):
    a, b, e, x = SLIDE_CASES[0]
    t = crank_angles(a, b, e, x)[1]
    scene = {"units": {"angle": "rad"}, "ground": {"A": [0, 0]},
             "links": {"AB": {"points": ["A", "B"], "length": a}, "BC": {"points": ["B", "C"], "length": b}},
             "slides": [{"name": "guide", "point": "C", "along": "ground", "line": {"through": [0, e]}}],
             "inputs": [{"slide": "guide", "value": x}],
             "guess": {"B": [a * math.cos(t) + 1e-3, a * math.sin(t) + 1e-3]},
             "output": {"report": ["AB.angle", "AB.omega"]}}
    path = write_scene(tmp_path, scene)
    code, out, err = run_cli(capsys, "modes", path, "--json", "--starts", "64")
    assert code == 0, err
    marked = [md for md in out["modes"] if md["from_guess"]]
    assert len(marked) == 1 and abs(wrapped(marked[0]["angles"]["AB"] - t)) <= 1e-9
    code, out, err = run_cli(capsys, "solve", path, "--json")
    assert code == 0, err
    assert out["values"]["AB.omega"][0] == pytest.approx(crank_omega(a, e, x, t), rel=1e-9)


# --- item 6 across groups: the quick return, only the ram E guessed ---

WHITWORTH = EXAMPLES / "whitworth.toml"


def whitworth_assemblies(th):
    """The four assemblies of examples/whitworth.toml at crank angle th: the lever B-D
    (100) points from B = 40 (cos th, sin th) towards the fixed pin A = (0, -20) or away from
    it; E on y = -20 at 150 from D, right or left of it. Each: {"D": ..., "E": ...}."""
    B, A = 40 * np.array([math.cos(th), math.sin(th)]), np.array([0.0, -20.0])
    out = []
    for lever in (1, -1):
        D = B + lever * 100 * (A - B) / np.linalg.norm(A - B)
        h = 150 ** 2 - (D[1] + 20) ** 2
        for side in (1, -1):
            if h >= 0:
                out.append({"D": D, "E": np.array([D[0] + side * math.sqrt(h), -20.0])})
    return out


@pytest.mark.parametrize("th_deg", [0.0, 40.0, 200.0])
def test_a_guessed_ram_places_the_lever_before_it(th_deg):
    """Only E is guessed: the lever's two ways through the slot (an earlier group) are
    decided by where E is wanted."""
    m0 = kincas.cli.scene.load(WHITWORTH).mechanism
    th = math.radians(th_deg)
    wanted = whitworth_assemblies(th)
    assert len(wanted) == 4
    for w in wanted:
        m = Mechanism(ground=m0.ground, links=m0.links, slides=m0.slides, inputs=m0.inputs,
                      guess={"E": tuple(w["E"] + 1e-3)})
        sw = kincas.sweep(m, {"crank.angle": [th]}, report=["D.x", "D.y", "E.x", "E.y"])
        assert sw.ok.all()
        got = {p: np.array([sw[f"{p}.x"][0], sw[f"{p}.y"][0]]) for p in "DE"}
        assert np.abs(got["D"] - w["D"]).max() <= 1e-9 * 150
        assert np.abs(got["E"] - w["E"]).max() <= 1e-9 * 150


# --- item 8: no [guess]: an assembly that runs the whole sweep ---


def whitworth_without_guess():
    doc = tomllib.loads(WHITWORTH.read_text())
    del doc["guess"]
    return kincas.cli.scene.loads(dump_toml(doc))


def chosen(sw):
    return [e for e in sw.events if e["kind"] == "assembly"]


def test_whitworth_without_guess_runs_all_73_poses():
    sc = whitworth_without_guess()
    assert not sc.mechanism.guess
    sw = sc.run()
    assert len(sw) == 73 and sw.ok.all()
    th = sw.inputs["crank.angle"]
    D = np.stack([sw["D.x"], sw["D.y"]], 1)
    E = np.stack([sw["E.x"], np.full(73, -20.0)], 1)  # the ram line
    far = lambda k, w: max(np.abs(D[k] - w["D"]).max(), np.abs(E[k] - w["E"]).max())
    # one assembly all the way round, one of the two with the lever pointing towards the pin
    # (pointing away, D rises out of the rod's reach: both of those fail 11 poses)
    [which] = [i for i, w in enumerate(whitworth_assemblies(th[0])) if far(0, w) <= 1e-9 * 150]
    assert which in (0, 1)
    assert all(far(k, whitworth_assemblies(th[k])[which]) <= 1e-9 * 150 for k in range(73))
    [e] = chosen(sw)
    assert e["pose"] == 0 and e["poses"] == 73
    assert "fails 11 of 73" in e["reason"] and "lever" in e["reason"]
    assert set(e["guess"]) == {"B", "D", "E"}


def test_cli_solve_prints_the_choice(capsys, tmp_path):
    doc = tomllib.loads(WHITWORTH.read_text())
    del doc["guess"]
    path = write_scene(tmp_path, dump_toml(doc))
    code, out, err = run_cli(capsys, "solve", path)
    assert code == 0, err
    assert "73 poses, 73 solved" in out
    line = next(ln for ln in out.splitlines() if "pose 0:" in ln and "assembly" in ln)
    assert "fails 11 of 73" in line


def test_a_guess_is_obeyed_even_where_its_branch_fails_poses():
    sc = kincas.cli.scene.load(WHITWORTH)
    th0 = sc.study.inputs["crank.angle"][0]
    away = whitworth_assemblies(th0)[2]  # lever away from the pin, E right of D: the default
    # without a guess, which fails 11 poses
    m = sc.mechanism
    m = Mechanism(ground=m.ground, links=m.links, slides=m.slides, inputs=m.inputs,
                  guess={"D": tuple(away["D"]), "E": tuple(away["E"])})
    sw = kincas.sweep(m, sc.study.inputs, report=["E.x", "D.x"])
    assert int(sw.ok.sum()) == 62 and not chosen(sw)
    assert sw["E.x"][0] == pytest.approx(away["E"][0], abs=1e-9 * 150)
    assert sw["D.x"][0] == pytest.approx(away["D"][0], abs=1e-9 * 150)


def test_a_sweep_that_no_assembly_runs_keeps_the_default():
    # a triple rocker swept round: no assembly exists near 180 deg, so none runs every pose
    m = Mechanism(ground={"A": (0, 0), "D": (4, 0)},
                  links=[Link.bar("crank", "A", "B", 1), Link.bar("coupler", "B", "C", 1.9),
                         Link.bar("rocker", "D", "C", 3)], inputs=[Input.angle("crank")])
    sw = kincas.sweep(m, {"crank.angle": np.linspace(0, 2 * np.pi, 37)}, report=["C.y"])
    assert not sw.ok.all() and not chosen(sw)
    assert sw["C.y"][0] > 0  # the default mode: B, D, C counter-clockwise


@pytest.mark.parametrize("th_deg", [75.0, 90.0, 105.0])
def test_without_guess_a_group_falls_back_to_its_other_mode(th_deg):
    """At these crank angles the lever pointing away from the pin (its default mode) leaves D
    out of the rod's reach: the documented rule takes the lever's other mode. (The group's
    search used to offer its first mode twice, so no assembly was found at all.)"""
    sc = whitworth_without_guess()
    th = math.radians(th_deg)
    pose = kincas.solve(sc.mechanism, {"crank.angle": th}, report=["D.x", "D.y", "E.x"])
    assert pose.status == "ok"
    got = np.array([pose["D.x"], pose["D.y"], pose["E.x"]])
    assert min(np.abs(got - [*w["D"], w["E"][0]]).max() for w in whitworth_assemblies(th)[:2]) <= 1e-9 * 150


def test_cli_modes_without_guess_marks_the_assembly_solve_takes(capsys, tmp_path):
    doc = tomllib.loads(WHITWORTH.read_text())
    del doc["guess"]
    path = write_scene(tmp_path, dump_toml(doc))
    code, out, err = run_cli(capsys, "modes", path, "--json", "--starts", "64")
    assert code == 0, err
    marked = [md for md in out["modes"] if md["from_guess"]]
    assert len(out["modes"]) == 4 and len(marked) == 1
    toward = [w["D"] for w in whitworth_assemblies(0.0)[:2]]
    assert min(np.abs(np.array(marked[0]["points"]["D"]) - D).max() for D in toward) <= 1e-9 * 150
    code, out, err = run_cli(capsys, "modes", path, "--starts", "64")
    assert out.count("<- `kincas solve` starts on this one (no [guess])") == 1
    assert "the scene's [guess]" not in out
