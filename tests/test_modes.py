"""Assembly modes (`kincas.analysis.modes`, `kincas modes`): every real assembly, each a ready [guess]
block, and a sweep from each one that stays on its own branch.

The answers are independent: circle intersections for the four-bar and the trammel, and for
the class-III triad the dense-sampling root finder of test_class3 (every assembly counted).
"""
from __future__ import annotations

import math
import tomllib

import numpy as np
import pytest

import kincas
import kincas.cli.scene
from conftest import EXAMPLES, run_cli, write_scene
from kincas import Input, Link, Mechanism, ModelError, Slide
from kincas.analysis.modes import Mode, find_modes
from kincas.cli.scene_guess import scene_with_guess
from test_class3 import POSITION_TOL, circles, match, track, triad_assemblies

TRIAD = EXAMPLES / "assur_triad.toml"


def fourbar(a=1.0, b=3.5, c=3.0, d=4.0, guess=(3.6, 2.9)):
    return Mechanism(ground={"A": (0, 0), "D": (d, 0)},
                     links=[Link.bar("crank", "A", "B", a), Link.bar("coupler", "B", "C", b),
                            Link.bar("rocker", "D", "C", c)],
                     inputs=[Input.angle("crank")], guess={"C": guess})


def triad_structure():
    """The triad with leg 3 fixed at 12 and no input: a structure (0 degrees of freedom)."""
    m = kincas.cli.scene.load(TRIAD).mechanism
    return Mechanism(parameters=m.parameters, ground=m.ground, links=m.links, inputs=[], guess=m.guess)


def block_points(text: str) -> dict[str, np.ndarray]:
    return {k: np.array(v, float) for k, v in tomllib.loads(text)["guess"].items()}


# ----------------------------------------------------------------------------- the API

def test_fourbar_has_the_two_circle_intersections():
    th = 1.0
    modes = find_modes(fourbar(), {"crank.angle": th}, starts=64)
    B = np.array([[math.cos(th)], [math.sin(th)]])
    expected = [{"B": B[:, 0], "C": circles(B, 3.5, np.array([[4.0], [0.0]]), 3.0, s)[:, 0]} for s in (1, -1)]
    match(modes, expected, 4.0, ["B", "C"])
    up = [md for md in modes if md.points["C"][1] > 0]
    assert [md.from_guess for md in up] == [True] and sum(md.from_guess for md in modes) == 1
    assert {md.orientation for md in modes} == {-1, 1}  # the two sides of the toggle positions
    assert math.isclose(up[0].angles["crank"], th, abs_tol=1e-15)


@pytest.mark.parametrize("seed", [0, 1, 2, 3])
def test_triad_six_modes_from_every_seed(seed):
    modes = find_modes(kincas.cli.scene.load(TRIAD).mechanism, 12.0, starts=256, seed=seed)
    match(modes, triad_assemblies(), 40.0, ["B1", "B2", "B3"])
    again = find_modes(kincas.cli.scene.load(TRIAD).mechanism, 12.0, starts=256, seed=seed)
    assert [md.points for md in again] == [md.points for md in modes]  # deterministic


def test_structure_without_inputs_has_the_same_six_modes():
    m = triad_structure()
    assert m.mobility == 0 and not m.inputs
    modes = find_modes(m)
    match(modes, triad_assemblies(), m.size(), ["B1", "B2", "B3"])
    assert all(md.inputs == {} for md in modes)


def test_floating_link_modes():
    """Trammel: a bar PQ of length 5 floats, P on the x axis (driven to s = 3), Q on the y
    axis: Q = (0, +-4)."""
    m = Mechanism(ground={"O": (0, 0)}, links=[Link.bar("bar", "P", "Q", 5.0)],
                  slides=[Slide("P", "ground", name="sx"),
                          Slide("Q", "ground", angle=math.pi / 2, name="sy")],
                  inputs=[Input.slide("sx")])
    assert "bar.x" in kincas.model_of(m).sym.unknowns[1]  # the bar floats: its origin is unknown
    modes = find_modes(m, {"sx.s": 3.0}, starts=64)
    match(modes, [{"P": np.array([3.0, 0]), "Q": np.array([0, s * 4.0])} for s in (1, -1)],
          5.0, ["P", "Q"])


def test_no_assembly_is_an_empty_list():
    modes = find_modes(fourbar(a=1, b=1, c=1, d=10), {"crank.angle": 0.3}, starts=64)
    assert modes == []


def test_bad_inputs_name_the_field():
    with pytest.raises(ModelError, match="inputs: 'nope' is not an input"):
        find_modes(fourbar(), {"nope": 1.0})
    with pytest.raises(ModelError, match="no value for input 'crank.angle'"):
        find_modes(fourbar(), {})
    with pytest.raises(ModelError, match="starts"):
        find_modes(fourbar(), 0.0, starts=0)


def test_guess_block_is_toml_that_gives_the_points_back():
    for md in find_modes(kincas.cli.scene.load(TRIAD).mechanism, 12.0):
        pts = block_points(md.guess_block())
        assert set(pts) == set(md.points)
        for p, xy in pts.items():
            assert np.abs(xy - md.points[p]).max() <= 1e-10 * 40, p


# ----------------------------------------------------------------------------- sweeping a mode

def test_every_triad_mode_sweeps_on_its_own_branch():
    """Leg 3 from 12 to 16 mm, started from each mode's guess: every pose on the branch that
    the independent solution tracks from that mode, the first pose the mode itself."""
    m = kincas.cli.scene.load(TRIAD).mechanism
    r3 = np.linspace(12, 16, 9)
    independent = [triad_assemblies(r, 50_001) for r in r3]
    report = [f"{p}.{c}" for p in ("B1", "B2", "B3") for c in "xy"]
    ends = []
    for md in find_modes(m, 12.0):
        sw = kincas.sweep(m, {"r3": r3}, guess=md.guess, report=report)
        assert sw.ok.all() and sw.residual.max() <= 1e-12
        first = {p: np.array([sw[f"{p}.x"][0], sw[f"{p}.y"][0]]) for p in md.points}
        assert all(np.abs(first[p] - md.points[p]).max() <= 1e-12 * 40 for p in md.points)
        branch, ratio = track(independent, {p: np.array(xy) for p, xy in md.points.items()})
        assert ratio.max() < 0.2
        for p in md.points:
            for c, i in (("x", 0), ("y", 1)):
                assert np.abs(sw[f"{p}.{c}"] - [b[p][i] for b in branch]).max() <= POSITION_TOL * 40
        ends.append(np.array([sw[f"{p}"][-1] for p in report]))
    # six branches, six different assemblies at the end too
    assert min(np.abs(a - b).max() for i, a in enumerate(ends) for b in ends[:i]) > 0.1


# ----------------------------------------------------------------------------- the command line

def test_cli_modes_json(capsys):
    code, out, err = run_cli(capsys, "modes", TRIAD, "--json")
    assert code == 0, err
    assert out["inputs"] == {"r3": 12.0} and out["units"]["length"] == "mm"
    modes = out["modes"]
    assert len(modes) == 6 and sum(md["from_guess"] for md in modes) == 1
    assert all(md["residual"] <= 1e-12 for md in modes)
    as_modes = [Mode(np.zeros(0), (), {p: tuple(xy) for p, xy in md["points"].items()}, {}, 0, 0)
                for md in modes]
    match(as_modes, triad_assemblies(), 40.0, ["B1", "B2", "B3"])
    for md in modes:
        pts = block_points(md["guess"])
        assert all(np.abs(pts[p] - md["points"][p]).max() <= 1e-10 * 40 for p in pts)
        # link angles in degrees, as the scene says: leg 1 points from A1 = (0, 0) to B1
        b1 = md["points"]["B1"]
        assert md["angles"]["leg1"] == pytest.approx(math.degrees(math.atan2(b1[1], b1[0])), abs=1e-9)


def test_cli_modes_text(capsys):
    code, out, err = run_cli(capsys, "modes", EXAMPLES / "stephenson3.toml", "--starts", "128")
    assert code == 0, err
    assert "2 assembly modes at driver.angle = 0 deg" in out
    blocks = ["[guess]\n" + b.split("\n\n")[0] for b in out.split("\n[guess]\n")[1:]]
    assert len(blocks) == 2 and out.count("<- the scene's [guess] gives this one") == 1
    for b in blocks:
        assert set(block_points(b)) == {"A", "B", "C", "D"}


def test_cli_writes_a_scene_per_mode_that_solves_on_it(capsys, tmp_path):
    code, out, err = run_cli(capsys, "modes", TRIAD, "--json", "--write", tmp_path / "modes")
    assert code == 0, err
    written = sorted((tmp_path / "modes").glob("assur_triad_mode*.toml"))
    assert [p.name for p in written] == [f"assur_triad_mode{k}.toml" for k in range(1, 7)]
    original = tomllib.loads(TRIAD.read_text())
    for path, md in zip(written, out["modes"]):
        scene = tomllib.loads(path.read_text())
        assert {k: v for k, v in scene.items() if k != "guess"} == \
            {k: v for k, v in original.items() if k != "guess"}
        code, sol, err = run_cli(capsys, "solve", path, "--json")
        assert code == 0, err
        for p, (x, y) in md["points"].items():
            assert abs(sol["values"][f"{p}.x"][0] - x) <= 1e-9 * 40
            assert abs(sol["values"][f"{p}.y"][0] - y) <= 1e-9 * 40


def test_cli_scene_without_inputs(capsys, tmp_path):
    text = TRIAD.read_text()
    text = text[:text.index("[[inputs]]")] + text[text.index("\n[guess]"):]
    code, out, err = run_cli(capsys, "modes", write_scene(tmp_path, text), "--json")
    assert code == 0, err
    assert out["inputs"] == {} and len(out["modes"]) == 6


def test_cli_no_assembly_exits_3(capsys, tmp_path):
    scene = ('[ground]\nA = [0, 0]\nD = [10, 0]\n[links]\ncrank = { points = ["A", "B"], length = 1 }\n'
             'coupler = { points = ["B", "C"], length = 1 }\nrocker = { points = ["D", "C"], length = 1 }\n'
             '[[inputs]]\nangle = "crank"\nvalue = 0\n')
    code, out, err = run_cli(capsys, "modes", write_scene(tmp_path, scene), "--starts", "32")
    assert code == 3, err
    assert "0 assembly modes" in out and "no assembly found" in out


def test_cli_errors_exit_2_without_traceback(capsys, tmp_path):
    code, out, err = run_cli(capsys, "modes", TRIAD, "--starts", "0")
    assert code == 2 and "--starts" in err and "Traceback" not in err
    bad = TRIAD.read_text().replace('length = "r3"', 'length = "r9"')
    code, out, err = run_cli(capsys, "modes", write_scene(tmp_path, bad))
    assert code == 2 and "[links] leg3: length: unknown parameter 'r9'" in err


# ----------------------------------------------------------------------------- scene text

def test_scene_with_guess_replaces_the_guess_table_only():
    md = Mode(np.zeros(0), (), {"C": (1.5, -2.0)}, {}, 0.0, 1)
    text = 'a = 1\n[guess]   # old\nC = [9, 9]\n\n# about output\n[output]\nreport = ["C.x"]\n'
    out = scene_with_guess(text, md, note="mode 2")
    assert out == 'a = 1\n# mode 2\n[guess]\nC = [1.5, -2]\n\n# about output\n[output]\nreport = ["C.x"]\n'
    assert scene_with_guess("a = 1", md) == "a = 1\n\n[guess]\nC = [1.5, -2]\n"
    with pytest.raises(kincas.SceneError, match=r"\[guess\]"):
        scene_with_guess('guess = { C = [1, 2] }\n', md)
