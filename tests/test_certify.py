"""Every assembly, certified (`kincas.modes(..., certify=True)`, `kincas modes --certify`).

The counts are known independently and written here: circle intersections for the four-bar,
the slider-crank and the Watt six-bar's dyads; the dense-sampling root finders of
test_class3 (every root of a one-variable residual over a full turn, both sides) for the
Assur triad (six assemblies, and four, two with a longer leg), the 3-RPR robot, the
Stephenson III six-bar and the class-IV eight-bar. A pose with none, a pose where two
assemblies coincide (multiplicity 2), refusals and the JSON contract complete it.
Each test's msolve runs take well under a second."""
from __future__ import annotations

import json
import math
import tomllib

import numpy as np
import pytest

import kincas
import kincas.cli.scene
from conftest import EXAMPLES, run_cli, write_scene
from kincas import Input, Link, Mechanism, Slide
from kincas.analysis import certify_msolve
from kincas.core.polynomial import Poly, PolySystem, unit
from kincas.core.polynomial_planar import NotPolynomial, closure
from kincas.core.tolerances import ACCEPT
from test_class3 import (circles, eightbar_assemblies, match, stephenson_assemblies, triad_assemblies,
                         triad_data)

needs_msolve = pytest.mark.skipif(not certify_msolve.available(),
                                  reason='msolve not installed (pip install "kincas[certify]")')


def certified(m, inputs):
    found = kincas.modes(m, inputs, certify=True)
    assert found.certified and found.count == len(found) and not found.rejected
    for md in found:  # every refined mode closes, and sits in its box
        assert md.residual <= ACCEPT and md.note == "" and md.halfwidth < 1e-12
    return found


def fourbar(a=1.0, b=3.5, c=3.0, d=4.0):
    return Mechanism(ground={"A": (0, 0), "D": (d, 0)},
                     links=[Link.bar("crank", "A", "B", a), Link.bar("coupler", "B", "C", b),
                            Link.bar("rocker", "D", "C", c)], inputs=[Input.angle("crank")])


# ----------------------------------------------------------------------------- exact writing

def test_polynomials_are_written_expanded_with_coprime_integer_coefficients():
    S = PolySystem()
    x, y = S.var("x"), S.var("y")
    S.equations.append((x - Poly.const(0.5)) * (x - 1) * 3 + y * 0.25)  # 3x^2 - 4.5x + 1.5 + y/4
    assert S.msolve_input().splitlines()[2] == "12*x0^2-18*x0+x1+6"


def test_linear_equations_solved_exactly_before_msolve():
    S = PolySystem()
    x, y, z = S.var("x"), S.var("y"), S.var("z")
    S.equations += [x + 2 * y - 3, y - z * Poly.const(0.5), x * x + z * z - 1]
    eqs, free, value = S.eliminated()
    assert free == [0] and len(eqs) == 1  # y and z from x: z = 2y = 3 - x
    assert value[2] == 3 - x and value[1] == (3 - x) * Poly.const(0.5)
    assert eqs[0] == x * x + (3 - x) * (3 - x) - 1
    T = PolySystem()
    a = T.var("a")
    T.equations += [a - 1, 2 * a - 3]
    assert T.eliminated() is None  # inconsistent: no solution


@pytest.mark.parametrize("deg", [0, 90, 180, -90, 30, 45, 123.456, -179.9])
def test_a_rounded_rotation_is_exact_and_near(deg):
    c, s, same = unit(math.radians(deg))
    assert c * c + s * s == 1  # an exact rotation, whatever the angle
    assert abs(math.atan2(float(s), float(c)) - math.radians(deg)) < 1e-11
    if deg % 90 == 0:
        assert same  # rational cos and sin: nothing rounded (others may round within 1 ulp)


def test_closure_equations_vanish_at_an_independent_assembly():
    th = math.pi / 2  # B = (0, 1) exactly; C from the circles
    B = np.array([[0.0], [1.0]])
    C = circles(B, 3.5, np.array([[4.0], [0.0]]), 3.0, 1)[:, 0]
    S = closure(fourbar(), [th])
    x = {"rocker.c": (C[0] - 4) / 3, "rocker.s": C[1] / 3, "coupler.c": C[0] / 3.5,
         "coupler.s": (C[1] - 1) / 3.5}
    assert max(abs(P.value([x[n] for n in S.names])) for P in S.equations) < 1e-14


def test_gears_racks_cams_are_refused_in_one_line(capsys):
    m = kincas.cli.scene.load(EXAMPLES / "geared_fivebar.toml").mechanism
    with pytest.raises(NotPolynomial, match=r"\[\[gears\]\]"):
        closure(m, [0.0])
    code, out, err = run_cli(capsys, "modes", EXAMPLES / "eccentric_cam.toml", "--certify")
    assert code == 2 and out == "" and len(err.strip().splitlines()) == 1 and "cam" in err


def test_missing_solver_one_line_exit_2(capsys, monkeypatch, tmp_path):
    monkeypatch.setenv("KINCAS_MSOLVE", str(tmp_path / "no-such-msolve"))
    code, out, err = run_cli(capsys, "modes", EXAMPLES / "fairbairn.toml", "--certify")
    assert code == 2 and len(err.strip().splitlines()) == 1 and "kincas[certify]" in err
    code, out, err = run_cli(capsys, "modes", EXAMPLES / "fairbairn.toml", "--starts", "16")
    assert code == 0 and "not certified" in out  # plain modes: the multistart, said so


def test_msolve_output_parsed_exactly():
    kind, boxes = certify_msolve.parse("[0, [1,\n[[[3 / 2^2, 7 / 2^3], [-1, -1]], [[0, 0], [5, 5]]]\n]]:")
    assert kind == "finite" and boxes[0] == [(0.75, 0.875), (-1, -1)] and len(boxes) == 2
    assert certify_msolve.parse("[1, 3, -1, []]:") == ("positive", [])
    assert certify_msolve.parse("[-1]:") == ("finite", [])  # not even a complex solution


# ----------------------------------------------------------------------------- known counts

@needs_msolve
def test_fourbar_two_assemblies_and_kincas_modes_is_callable():
    import kincas.modes as old_path  # the 0.1 module path still imports
    th = 1.0
    found = certified(fourbar(), {"crank.angle": th})
    B = np.array([[math.cos(th)], [math.sin(th)]])
    expected = [{"B": B[:, 0], "C": circles(B, 3.5, np.array([[4.0], [0.0]]), 3.0, s)[:, 0]} for s in (1, -1)]
    match(found, expected, 4.0, ["B", "C"])
    assert found.rounded and "taken as" in found.rounded[0]  # 1 rad: the certificate's pose is rounded
    assert abs(found.inputs["crank.angle"] - th) < 1e-11
    assert old_path(fourbar(), th, starts=32).certified is False
    assert [md.multiplicity for md in found] == [1, 1] and {md.flag for md in found} == {""}


@needs_msolve
def test_slider_crank_two_assemblies():
    r, l, e = 2.0, 5.0, 1.0  # offset slider-crank: B on the line y = e
    m = Mechanism(ground={"O": (0, 0)}, links=[Link.bar("crank", "O", "A", r), Link.bar("rod", "A", "B", l)],
                  slides=[Slide("B", "ground", through=(0, e))], inputs=[Input.angle("crank")])
    th = math.radians(90)
    found = certified(m, th)
    assert found.rounded == []  # 90 degrees: exact
    Ax, Ay = r * math.cos(th), r * math.sin(th)
    xs = [Ax + sg * math.sqrt(l * l - (e - Ay) ** 2) for sg in (1, -1)]
    match(found, [{"B": np.array([x, e])} for x in xs], l, ["B"])


@needs_msolve
@pytest.mark.parametrize("r3, count", [(12, 6), (28, 2)])
def test_assur_triad_six_then_fewer(r3, count):
    m = kincas.cli.scene.load(EXAMPLES / "assur_triad.toml").mechanism
    expected = triad_assemblies(r3, 50_001)
    assert len(expected) == count  # independently
    match(certified(m, float(r3)), expected, 40.0, ["B1", "B2", "B3"])


@needs_msolve
def test_planar_3rpr_with_prismatic_legs():
    """The 3-RPR robot as built: each leg a cylinder pivoted on the ground with the platform's
    joint sliding along it, the three leg lengths its inputs (a triad's forward kinematics:
    six complex solutions): with leg 3 at 24, four of them real."""
    g, d2, d3, alpha, (r1, r2, r3) = triad_data()
    plate = Link("plate", {"B1": (0, 0), "B2": (d2, 0), "B3": (d3 * math.cos(alpha), d3 * math.sin(alpha))})
    m = Mechanism(ground={k: tuple(v) for k, v in g.items()},
                  links=[Link(f"leg{k}", {f"A{k}": (0, 0), f"T{k}": (1, 0)}) for k in (1, 2, 3)] + [plate],
                  slides=[Slide(f"B{k}", f"leg{k}", name=f"s{k}") for k in (1, 2, 3)],
                  inputs=[Input.slide(f"s{k}") for k in (1, 2, 3)])
    for legs, count in (((r1, r2, 24.0), 4),):
        expected = triad_assemblies(legs[2], 50_001)
        assert len(expected) == count
        found = certified(m, {f"s{k}.s": v for k, v in zip((1, 2, 3), legs)})
        match(found, expected, 40.0, ["B1", "B2", "B3"])


@needs_msolve
@pytest.mark.parametrize("scene, deg, independent, points", [
    ("stephenson3", 100, stephenson_assemblies, ["A", "B", "C", "D"]),  # driven through its triad
    ("eightbar", 60, eightbar_assemblies, ["E", "P", "Q", "R", "S", "H", "G"])])  # a class-IV group
def test_stephenson_six_bar_and_class_iv_eight_bar(scene, deg, independent, points):
    m = kincas.cli.scene.load(EXAMPLES / f"{scene}.toml").mechanism
    expected = independent(math.radians(deg), 50_001)
    assert len(expected) == 2
    match(certified(m, math.radians(deg)), expected, m.size(), points)


@needs_msolve
def test_watt_six_bar_four_assemblies():
    """Four-bar O2-A-B-O4 whose ternary rocker O4-B-C drives the dyad C-D-O6: 2 x 2."""
    m = Mechanism(ground={"O2": (0, 0), "O4": (4, 0), "O6": (5, 1)},
                  links=[Link.bar("crank", "O2", "A", 1), Link.bar("coupler", "A", "B", 3.5),
                         Link("rocker", {"O4": (0, 0), "B": (3, 0), "C": (2, 1.5)}),
                         Link.bar("rod", "C", "D", 3), Link.bar("out", "O6", "D", 2.5)],
                  inputs=[Input.angle("crank")])
    th = 0.0
    A = np.array([[1.0], [0.0]])
    expected = []
    for s1 in (1, -1):
        B = circles(A, 3.5, np.array([[4.0], [0.0]]), 3.0, s1)[:, 0]
        phi = math.atan2(B[1], B[0] - 4)
        C = np.array([4 + 2 * math.cos(phi) - 1.5 * math.sin(phi), 2 * math.sin(phi) + 1.5 * math.cos(phi)])
        for s2 in (1, -1):
            D = circles(C[:, None], 3.0, np.array([[5.0], [1.0]]), 2.5, s2)[:, 0]
            expected.append({"A": A[:, 0], "B": B, "C": C, "D": D})
    assert all(np.isfinite(a["D"]).all() for a in expected)
    match(certified(m, th), expected, m.size(), ["A", "B", "C", "D"])


# ----------------------------------------------------------------------------- none, singular

@needs_msolve
def test_no_assembly_count_zero_exit_3(capsys, tmp_path):
    found = certified(fourbar(a=3.0, b=1.0, c=1.0), math.pi)  # |BD| = 7 > 1 + 1
    assert found.count == 0 and not found.ok
    text = (EXAMPLES / "fairbairn.toml").read_text(encoding="utf-8")
    scene = write_scene(tmp_path, text.replace("a62 = 550", "a62 = 50"))  # E never reaches the guide
    code, out, err = run_cli(capsys, "modes", scene, "--certify", "--json")
    assert code == 3 and out["certified"] is True and out["count"] == 0 and out["modes"] == []


@needs_msolve
def test_coinciding_assemblies_listed_once_multiplicity_two():
    """Crank 3 at 90 deg puts B at (0, 3), 5 from D = (4, 0): coupler 2 + rocker 3 reach it
    only stretched in line, C = B + (2/5)(D - B) = (1.6, 1.8), where the two assemblies meet."""
    found = certified(fourbar(a=3.0, b=2.0, c=3.0), math.pi / 2)
    assert found.count == 1 and found.rounded == []
    md = found[0]
    assert md.multiplicity == 2 and md.flag == "singular" and md.orientation == 0
    assert np.allclose(md.points["C"], (1.6, 1.8), atol=1e-12)


@needs_msolve
def test_infinitely_many_assemblies_reported(capsys, tmp_path):
    """Crank 4 at 0 puts B on D: coupler 2 and rocker 2 then let C turn on a whole circle."""
    found = kincas.modes(fourbar(a=4.0, b=2.0, c=2.0), 0.0, certify=True)
    assert found.positive_dimension and found.count is None and len(found) == 0
    scene = {"ground": {"A": [0, 0], "D": [4, 0]},
             "links": {"crank": {"points": ["A", "B"], "length": 4},
                       "coupler": {"points": ["B", "C"], "length": 2},
                       "rocker": {"points": ["D", "C"], "length": 2}},
             "inputs": [{"angle": "crank", "value": 0}], "guess": {"C": [4, 2]}}
    code, out, err = run_cli(capsys, "modes", write_scene(tmp_path, scene), "--certify", "--json")
    assert code == 3 and out["positive_dimension"] is True and out["count"] is None


# ----------------------------------------------------------------------------- the CLI's contract

@needs_msolve
def test_cli_json_contract_and_scenes_written(capsys, tmp_path):
    code, out, err = run_cli(capsys, "modes", EXAMPLES / "assur_triad.toml", "--certify", "--json",
                             "--write", tmp_path / "modes")
    assert code == 0, err
    assert out["certified"] is True and out["count"] == 6 == len(out["modes"])
    for md in out["modes"]:
        assert {"points", "angles", "residual", "guess", "halfwidth", "multiplicity", "flag"} <= set(md)
        assert md["multiplicity"] == 1 and md["flag"] == "" and 0 <= md["halfwidth"] < 1e-12
        assert md["residual"] <= ACCEPT
    written = sorted((tmp_path / "modes").glob("assur_triad_mode*.toml"))
    assert len(written) == 6
    for path, md in zip(written, out["modes"]):
        guess = tomllib.loads(path.read_text(encoding="utf-8"))["guess"]
        assert max(abs(a - b) for p in guess for a, b in zip(guess[p], md["points"][p])) < 1e-9
    code, text, err = run_cli(capsys, "modes", EXAMPLES / "fairbairn.toml", "--certify")
    assert code == 0 and "certified" in text and "not certified" not in text and "count 2" in text
    guessless = (EXAMPLES / "fairbairn.toml").read_text(encoding="utf-8").split("[guess]")[0]
    code, out, err = run_cli(capsys, "modes", write_scene(tmp_path, guessless), "--certify", "--json")
    assert code == 0 and out["certified"] is True and out["count"] == 2  # still certified
    json.dumps(out)  # plain JSON


# ----------------------------------------------------------------------------- the subprocess

def fake_msolve(tmp_path, body):
    exe = tmp_path / "msolve"
    exe.write_text("#!/bin/sh\n" + body + "\n", encoding="utf-8")
    exe.chmod(0o755)
    return exe


def test_a_slow_solver_is_killed_at_its_timeout_and_on_cancel(tmp_path, monkeypatch):
    import threading
    import time

    from kincas.core.cancel import Cancelled, Token, cancelling
    pidfile = tmp_path / "pid"
    monkeypatch.setenv("KINCAS_MSOLVE", str(fake_msolve(tmp_path, f"echo $$ > {pidfile}; exec sleep 30")))
    t0 = time.monotonic()
    with pytest.raises(certify_msolve.SolverFailed, match="longer than"):
        certify_msolve.solve("x0\n0\nx0", timeout=0.5)
    assert time.monotonic() - t0 < 5

    def gone():
        pid = int(pidfile.read_text())
        try:
            import os
            os.kill(pid, 0)
        except ProcessLookupError:
            return True
        return False
    assert gone()
    token, caught = Token(), []

    def work():
        with cancelling(token):
            try:
                certify_msolve.solve("x0\n0\nx0", timeout=60)
            except Cancelled:
                caught.append(True)
    pidfile.unlink()
    th = threading.Thread(target=work)
    th.start()
    while not pidfile.exists():
        time.sleep(0.01)
    token.cancel()  # what Ctrl-C does to the work it interrupts
    th.join(5)
    assert caught == [True] and not th.is_alive() and gone()


def test_a_solver_that_fails_or_babbles_is_an_error(tmp_path, monkeypatch):
    monkeypatch.setenv("KINCAS_MSOLVE", str(fake_msolve(tmp_path, "exit 1")))
    with pytest.raises(certify_msolve.SolverFailed):
        certify_msolve.solve("x0\n0\nx0")
    monkeypatch.setenv("KINCAS_MSOLVE", str(fake_msolve(tmp_path, 'while [ $# -gt 0 ]; do [ "$1" = -o ] && o=$2; shift; done; echo "what?" > "$o"')))
    with pytest.raises(certify_msolve.SolverFailed, match="not understood"):
        certify_msolve.solve("x0\n0\nx0")


# ----------------------------------------------------------------------------- Assur group 4.4

# Class 4, order 4: the ternary links T1..T4 close a quadrilateral J1 J2 J3 J4 (T_i carries
# J_i, J_i+1 and P_i), each held to the ground by a binary leg G_i P_i. 56 complex assemblies
# for generic dimensions. This integer geometry (found by a random search, kept for its count)
# has 10 real ones.
G44 = {"G1": (127, 19), "G2": (-98, -23), "G3": (-148, -119), "G4": (-7, 240)}
LEGS44 = (153, 108, 135, 253)
TERN44 = ((74, 29, 76), (110, 3, -12), (103, -7, -17), (125, 12, -17))  # |J_i J_i+1|, P_i in T_i's frame


def group44():
    links = []
    for i in range(4):
        a, b = f"J{i + 1}", f"J{(i + 1) % 4 + 1}"
        L, px, py = TERN44[i]
        links += [Link.bar(f"leg{i + 1}", f"G{i + 1}", f"P{i + 1}", LEGS44[i]),
                  Link(f"T{i + 1}", {a: (0, 0), b: (L, 0), f"P{i + 1}": (px, py)})]
    return Mechanism(ground=G44, links=links)


def group44_assemblies(starts=800, seed=1):
    """Independently: the angles of leg 1 (t) and of T1, T2, T4 place leg 1, then T1 (J1,
    J2) from P1, T2 from J2 and T4 from J1; four equations: P2 and P4 on their legs' circles,
    J3J4 of T3's length, and P3 (T3 placed on J3 towards J4) on leg 3's circle. Newton with
    central differences from random starts (every angle uniform), the distinct roots
    polished by mpmath at 30 digits (each a real root to 1e-20)."""
    import mpmath as mp
    g = {k: (float(x), float(y)) for k, (x, y) in G44.items()}
    (L1, p1x, p1y), (L2, p2x, p2y), (L3, p3x, p3y), (L4, p4x, p4y) = TERN44
    l1, l2, l3, l4 = LEGS44

    def place(t, f1, f2, f4, lib=np):
        cos, sin = lib.cos, lib.sin
        atan2 = mp.atan2 if lib is mp else np.arctan2
        R = lambda a, x, y: (cos(a) * x - sin(a) * y, sin(a) * x + cos(a) * y)
        add = lambda p, q, s=1: (p[0] + s * q[0], p[1] + s * q[1])
        P1 = (g["G1"][0] + l1 * cos(t), g["G1"][1] + l1 * sin(t))
        J1 = add(P1, R(f1, p1x, p1y), -1)
        J2 = add(J1, R(f1, L1, 0))
        P2, J3 = add(J2, R(f2, p2x, p2y)), add(J2, R(f2, L2, 0))
        P4, J4 = add(J1, R(f4, p4x - L4, p4y)), add(J1, R(f4, -L4, 0))
        f3 = atan2(J4[1] - J3[1], J4[0] - J3[0])
        P3 = add(J3, R(f3, p3x, p3y))
        d2 = lambda p, q: (p[0] - q[0]) ** 2 + (p[1] - q[1]) ** 2
        res = (d2(P2, g["G2"]) - l2 * l2, d2(P4, g["G4"]) - l4 * l4, d2(J4, J3) - L3 * L3,
               d2(P3, g["G3"]) - l3 * l3)
        return res, {"J1": J1, "J2": J2, "J3": J3, "J4": J4, "P1": P1, "P2": P2, "P3": P3, "P4": P4}

    x = np.random.default_rng(seed).uniform(-math.pi, math.pi, (4, starts))
    F = lambda x: np.array(place(*x)[0])
    h = 1e-7
    with np.errstate(invalid="ignore", divide="ignore"):
        for _ in range(40):
            r = F(x)
            J = np.stack([(F(x + h * np.eye(4)[:, [j]]) - F(x - h * np.eye(4)[:, [j]])) / (2 * h)
                          for j in range(4)], axis=1)  # 4 x 4 x starts
            step = np.linalg.solve(J.transpose(2, 0, 1), r.T[:, :, None])[:, :, 0].T
            x = x - np.clip(np.nan_to_num(step, nan=0.0), -0.5, 0.5)
        r = np.abs(F(x)).max(axis=0)
    found = []
    for root in x[:, np.isfinite(r) & (r < 1e-6)].T:
        pts = place(*root)[1]
        row = np.array([c for k in sorted(pts) for c in pts[k]])
        if all(np.abs(row - other).max() > 1e-6 for other, _ in found):
            found.append((row, root))
    mp.mp.dps = 30
    out = []
    for _, root in found:
        z = mp.findroot(lambda *a: place(*a, lib=mp)[0], [mp.mpf(float(v)) for v in root])
        res, pts = place(*z, lib=mp)
        assert max(abs(v) for v in res) < mp.mpf(10) ** -20
        out.append({k: np.array([float(p[0]), float(p[1])]) for k, p in pts.items()})
    return out


@needs_msolve
def test_assur_group_44_ten_real_of_56():
    m = group44()
    expected = group44_assemblies()
    assert len(expected) == 10  # the independent search finds ten distinct real assemblies
    found = certified(m, None)
    match(found, expected, m.size(), ["J1", "J2", "J3", "J4", "P1", "P2", "P3", "P4"])
    S = closure(m, [])
    eqs, free, _ = S.eliminated()
    assert certify_msolve.complex_count(S.msolve_input(eqs, free)) == 56
