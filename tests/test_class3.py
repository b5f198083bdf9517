"""Chains that no dyad method solves: the Assur class-III triad, a Stephenson III six-bar driven
through its triad, an eight-bar with a class-IV group. Each is checked against an independent
solution written here in numpy: the chain reduced to one unknown angle by circle
intersections, the closure residual sampled densely over a whole turn, every sign change
bracketed and bisected to machine precision. That gives every real assembly (the modes are
counted, not only the one kincas follows) and, tracked by continuity, the branch of a sweep.
"""
from __future__ import annotations

import math
import tomllib

import numpy as np
import pytest

import kincas
import kincas.cli.scene
from conftest import EXAMPLES, run_cli
from kincas.analysis.modes import find_modes

POSITION_TOL = 1e-9  # relative to the mechanism's size
ANGLE_TOL = 1e-9  # radians


# ----------------------------------------------------------------------------- independent tools

def circles(c1, r1, c2, r2, side):
    """Intersection of circle (c1, r1) and circle (c2, r2) (centres 2 x n): the point on the
    left of c1 -> c2 for side = +1, on the right for -1; NaN where they do not meet."""
    e = c2 - c1
    d = np.linalg.norm(e, axis=0)
    x = (r1 * r1 - r2 * r2 + d * d) / (2 * d)
    with np.errstate(invalid="ignore"):
        h = np.sqrt(r1 * r1 - x * x)
    e = e / d
    return c1 + x * e + side * h * np.stack([-e[1], e[0]])


def rot(a, v):
    """The local vector v = (x, y) turned by the angles a (n,): 2 x n."""
    c, s = np.cos(a), np.sin(a)
    return np.stack([c * v[0] - s * v[1], s * v[0] + c * v[1]])


def e(a):
    return np.stack([np.cos(a), np.sin(a)])


def roots(f, n=200_001):
    """Every root of the scalar function f over (-pi, pi]: f(t) is vectorised and NaN where
    undefined. Sign changes between finite neighbours on a grid of n points, then 80
    bisections of every bracket at once (the bracket shrinks below machine precision)."""
    t = np.linspace(-math.pi, math.pi, n)
    v = f(t)
    k = np.flatnonzero(np.isfinite(v[:-1]) & np.isfinite(v[1:]) & (np.sign(v[:-1]) * np.sign(v[1:]) < 0))
    a, b, fa = t[k], t[k + 1], v[k]
    for _ in range(80):
        m = 0.5 * (a + b)
        fm = f(m)
        left = np.sign(fm) == np.sign(fa)
        a, fa, b = np.where(left, m, a), np.where(left, fm, fa), np.where(left, b, m)
    return 0.5 * (a + b)


def track(candidates_per_pose, start):
    """Follow one branch: at each pose the candidate (a dict of point -> (2,) arrays) nearest
    to the one before; returns the chosen dicts and the ratio of the nearest distance to the
    second nearest at each step (small: the choice is unambiguous)."""
    chosen, ratios, prev = [], [], start
    for cands in candidates_per_pose:
        d = [max(np.linalg.norm(c[p] - prev[p]) for p in prev) for c in cands]
        order = np.argsort(d)
        chosen.append(cands[order[0]])
        ratios.append(d[order[0]] / d[order[1]] if len(d) > 1 else 0.0)
        prev = {p: chosen[-1][p] for p in prev}
    return chosen, np.array(ratios)


def scene_numbers(path):
    """The scene's TOML with a helper resolving numbers given as parameter names."""
    sc = tomllib.loads(path.read_text(encoding="utf-8"))
    par = sc.get("parameters", {})

    def num(v):
        return float(par[v]) if isinstance(v, str) else float(v)

    def vec(v):
        return np.array([num(v[0]), num(v[1])])
    return sc, num, vec


def match(modes, assemblies, size, names):
    """Pair kincas's modes with the independent assemblies one to one, within the tolerance."""
    assert len(modes) == len(assemblies), (len(modes), len(assemblies))
    unused = list(range(len(assemblies)))
    for md in modes:
        err = [max(np.abs(np.array(md.points[p]) - assemblies[j][p]).max() for p in names) for j in unused]
        j = int(np.argmin(err))
        assert err[j] <= POSITION_TOL * size, f"mode {md.points} matches no assembly (error {err[j]:.3g})"
        unused.pop(j)


# ----------------------------------------------------------------------------- which chains dyads solve

def dyad_solvable(scene: dict) -> bool:
    """Whether placing points dyad by dyad from the ground and the driven link reaches every
    point: a link with two placed points is placed whole; an unplaced point held by two
    links that each have a placed point is placed by a circle intersection (an RRR dyad)."""
    links = {k: (list(v["points"]) if isinstance(v["points"], list) else list(v["points"]))
             for k, v in scene["links"].items()}
    placed = set(scene["ground"])
    for spec in scene["inputs"]:
        if "angle" in spec:  # a driven link on a placed pivot is placed whole
            pts = links[spec["angle"]]
            if placed & set(pts):
                placed |= set(pts)
    while True:
        before = len(placed)
        for pts in links.values():
            if len(placed & set(pts)) >= 2:
                placed |= set(pts)
        for p in {p for pts in links.values() for p in pts} - placed:
            holders = [pts for pts in links.values() if p in pts and placed & set(pts)]
            if len(holders) >= 2:
                placed.add(p)
        if len(placed) == before:
            return placed >= {p for pts in links.values() for p in pts}


FOURBAR = {"ground": {"A": [0, 0], "D": [4, 0]},
           "links": {"crank": {"points": ["A", "B"]}, "coupler": {"points": ["B", "C"]},
                     "rocker": {"points": ["D", "C"]}},
           "inputs": [{"angle": "crank"}]}


def test_dyad_check_tells_a_fourbar_from_the_class3_and_class4_examples():
    assert dyad_solvable(FOURBAR)
    stephenson = tomllib.loads((EXAMPLES / "stephenson3.toml").read_text())
    driven_at_crank = {**stephenson, "inputs": [{"angle": "crank"}]}
    assert dyad_solvable(driven_at_crank)  # the same chain driven at O2A: four-bar plus dyad
    for name in ("assur_triad", "stephenson3", "eightbar"):
        assert not dyad_solvable(tomllib.loads((EXAMPLES / f"{name}.toml").read_text())), name


# ----------------------------------------------------------------------------- the class-III triad

def triad_data(path=EXAMPLES / "assur_triad.toml"):
    sc, num, vec = scene_numbers(path)
    g = {k: vec(v) for k, v in sc["ground"].items()}
    plate = sc["links"]["plate"]["points"]
    b2, b3 = vec(plate["B2"]), vec(plate["B3"])
    assert np.allclose(vec(plate["B1"]), 0) and b2[1] == 0
    legs = [num(sc["links"][f"leg{i}"]["length"]) for i in (1, 2, 3)]
    return g, b2[0], np.linalg.norm(b3), math.atan2(b3[1], b3[0]), legs


def triad_assemblies(r3=None, n=200_001):
    """Every real assembly of the triad with leg 3 of length r3, independently: for a plate
    angle phi, B1 lies on the circle about A1 and on the circle about A2 - B1B2(phi); the
    residual is leg 3's length error at B3 = B1 + B1B3(phi)."""
    g, d2, d3, alpha, (r1, r2, r3_) = triad_data()
    r3 = r3_ if r3 is None else r3
    A1, A2, A3 = (g[k][:, None] for k in ("A1", "A2", "A3"))
    out = []
    for side in (1, -1):
        def pose(phi):
            b1 = circles(A1, r1, A2 - d2 * e(phi), r2, side)
            return b1, b1 + d2 * e(phi), b1 + d3 * e(phi + alpha)

        def f(phi):
            b3 = pose(phi)[2]
            return np.sum((b3 - A3) ** 2, axis=0) - r3 * r3
        for phi in roots(f, n):
            b1, b2, b3 = (p[:, 0] for p in pose(np.array([phi])))
            out.append({"B1": b1, "B2": b2, "B3": b3, "phi": phi})
    return out


def triad_mechanism():
    return kincas.cli.scene.load(EXAMPLES / "assur_triad.toml").mechanism


def test_independent_triad_method_finds_six_assemblies_that_close():
    g, d2, d3, alpha, (r1, r2, r3) = triad_data()
    found = triad_assemblies()
    assert len(found) == 6
    for a in found:  # every constraint, checked directly
        assert abs(np.linalg.norm(a["B1"] - g["A1"]) - r1) < 1e-12 * 20
        assert abs(np.linalg.norm(a["B2"] - g["A2"]) - r2) < 1e-12 * 20
        assert abs(np.linalg.norm(a["B3"] - g["A3"]) - r3) < 1e-12 * 20
        assert abs(np.linalg.norm(a["B2"] - a["B1"]) - d2) < 1e-12 * 20
        assert abs(np.linalg.norm(a["B3"] - a["B1"]) - d3) < 1e-12 * 20
    # the numbers: the plate's sides 0.882603 rad apart
    assert alpha == pytest.approx(0.882603, abs=1e-15)
    assert d3 == pytest.approx(20.84, abs=1e-14)


def test_kincas_finds_the_six_triad_assemblies():
    m = triad_mechanism()
    modes = find_modes(m, {"r3": 12.0})
    assert len(modes) == 6
    match(modes, triad_assemblies(), m.size(), ["B1", "B2", "B3"])
    assert all(md.residual <= 1e-12 for md in modes)
    assert sum(md.from_guess for md in modes) == 1
    assert sorted(md.orientation for md in modes) == [-1, -1, -1, 1, 1, 1]


def test_triad_example_sweep_follows_its_branch(capsys):
    """`kincas solve` on the example (leg 3 from 12 to 16 mm) against the independent branch
    that starts at the scene's guess."""
    code, out, err = run_cli(capsys, "solve", EXAMPLES / "assur_triad.toml", "--json")
    assert code == 0, err
    r3 = np.array(out["inputs"]["r3"])
    sc, _, vec = scene_numbers(EXAMPLES / "assur_triad.toml")
    start = {k: vec(v) for k, v in sc["guess"].items()}
    branch, ratio = track([triad_assemblies(r, 50_001) for r in r3], start)
    assert ratio.max() < 0.2  # the branch is never in doubt
    size = triad_mechanism().size()
    for p in ("B1", "B2", "B3"):
        for c, i in (("x", 0), ("y", 1)):
            got = np.array(out["values"][f"{p}.{c}"])
            assert np.abs(got - [b[p][i] for b in branch]).max() <= POSITION_TOL * size, p + c
    phi = np.array([b["phi"] for b in branch])
    err = np.angle(np.exp(1j * (np.radians(out["values"]["plate.angle"]) - phi)))
    assert np.abs(err).max() <= ANGLE_TOL


# ----------------------------------------------------------------------------- Stephenson III

def stephenson_data():
    sc, num, vec = scene_numbers(EXAMPLES / "stephenson3.toml")
    P = {k: num(v) for k, v in sc["parameters"].items()}
    g = {k: vec(v) for k, v in sc["ground"].items()}
    return sc, P, g


def stephenson_assemblies(driver_angle, n=50_001):
    """With D placed by the driver, the crank angle theta alone fixes A, then B (circle
    intersection with the rocker, either side), then C on the coupler; the residual is the
    rod's length error. Every root over a full turn of the crank, on both sides."""
    sc, P, g = stephenson_data()
    D = g["O6"] + P["e"] * np.array([math.cos(driver_angle), math.sin(driver_angle)])
    out = []
    for side in (1, -1):
        def pose(th):
            A = g["O2"][:, None] + P["r2"] * e(th)
            B = circles(A, P["r3"], g["O4"][:, None], P["r4"], side)
            phi = np.arctan2(B[1] - A[1], B[0] - A[0])
            return A, B, A + rot(phi, (P["cx"], P["cy"])), phi

        def f(th):
            return np.sum((pose(th)[2] - D[:, None]) ** 2, axis=0) - P["l"] ** 2
        for th in roots(f, n):
            A, B, C, phi = (np.ravel(x) if np.ndim(x) == 1 else x[:, 0] for x in pose(np.array([th])))
            out.append({"A": A, "B": B, "C": C, "D": D, "crank": th, "coupler": float(phi[0])})
    return out


def test_stephenson3_sweep_matches_the_independent_branch(capsys):
    """The example as shipped (the driver turned once): positions, angles, and the crank's
    angular velocity against a 5-point central difference of the independent solution."""
    code, out, err = run_cli(capsys, "solve", EXAMPLES / "stephenson3.toml", "--json")
    assert code == 0, err
    sc, P, g = stephenson_data()
    psi = np.radians(out["inputs"]["driver.angle"])
    start = {k: np.array(v, float) for k, v in sc["guess"].items()}
    branch, ratio = track([stephenson_assemblies(a) for a in psi], start)
    assert ratio.max() < 0.2
    size = kincas.cli.scene.load(EXAMPLES / "stephenson3.toml").mechanism.size()
    for p in ("A", "B", "C"):
        for c, i in (("x", 0), ("y", 1)):
            got = np.array(out["values"][f"{p}.{c}"])
            assert np.abs(got - [b[p][i] for b in branch]).max() <= POSITION_TOL * size, p + c
    for link in ("crank", "coupler"):
        err = np.angle(np.exp(1j * (np.radians(out["values"][f"{link}.angle"]) - [b[link] for b in branch])))
        assert np.abs(err).max() <= ANGLE_TOL, link
    # crank.omega = d(crank)/d(driver) * rate, at a few poses (rate 60 deg/s)
    h, rate = 1e-3, math.radians(sc["inputs"][0]["rate"])
    for k in (0, len(psi) // 3, 2 * len(psi) // 3):
        ths = []
        for j in (-2, -1, 1, 2):
            cand = stephenson_assemblies(psi[k] + j * h)
            ths.append(min(cand, key=lambda c: np.linalg.norm(c["A"] - branch[k]["A"]))["crank"])
        d1 = (ths[0] - 8 * ths[1] + 8 * ths[2] - ths[3]) / (12 * h)
        assert math.radians(out["values"]["crank.omega"][k]) == pytest.approx(d1 * rate, rel=1e-7)


@pytest.mark.parametrize("driver_deg", [0, 100, 250])
def test_stephenson3_modes_are_all_the_triad_assemblies(driver_deg):
    m = kincas.cli.scene.load(EXAMPLES / "stephenson3.toml").mechanism
    a = math.radians(driver_deg)
    found = stephenson_assemblies(a, 200_001)
    assert len(found) >= 2
    match(find_modes(m, {"driver.angle": a}), found, m.size(), ["A", "B", "C", "D"])


# ----------------------------------------------------------------------------- eight-bar, class IV

def eightbar_assemblies(crank_angle, n=50_001):
    """With E placed by the crank, the lever's angle phi alone fixes P, Q and H; R is where the
    circle about P (link PR) meets the circle about E (the floater's side RE), either side,
    which turns the floater; the residual is link QS's length error at S. The output dyad
    H-G-O3 adds its two circle intersections to each root."""
    sc, num, vec = scene_numbers(EXAMPLES / "eightbar.toml")
    P = {k: num(v) for k, v in sc["parameters"].items()}
    g = {k: vec(v) for k, v in sc["ground"].items()}
    E = g["O1"] + P["rc"] * np.array([math.cos(crank_angle), math.sin(crank_angle)])
    e_loc = np.array([P["ex"], P["ey"]])
    out = []
    for side in (1, -1):
        def pose(phi):
            p, q = rot(phi, (P["px"], 0.0)), rot(phi, (P["qx"], P["qy"]))
            R = circles(p, P["b1"], np.repeat(E[:, None], np.size(phi), axis=1), np.linalg.norm(e_loc), side)
            psi = np.arctan2(E[1] - R[1], E[0] - R[0]) - math.atan2(e_loc[1], e_loc[0])
            return p, q, R, R + rot(psi, (P["sx"], 0.0)), psi

        def f(phi):
            p, q, R, S, _ = pose(phi)
            return np.sum((S - q) ** 2, axis=0) - P["b2"] ** 2
        for phi in roots(f, n):
            p, q, R, S, psi = (x[:, 0] if np.ndim(x) == 2 else x for x in pose(np.array([phi])))
            H = rot(np.array([phi]), (P["hx"], P["hy"]))
            for side2 in (1, -1):
                G = circles(H, P["l"], g["O3"][:, None], P["rr"], side2)[:, 0]
                if np.all(np.isfinite(G)):
                    out.append({"E": E, "P": p, "Q": q, "R": R, "S": S, "H": H[:, 0], "G": G,
                                "lever": phi, "floater": float(psi[0])})
    return out


def test_eightbar_sweep_matches_the_independent_branch(capsys):
    code, out, err = run_cli(capsys, "solve", EXAMPLES / "eightbar.toml", "--json")
    assert code == 0, err
    sc, _, _ = scene_numbers(EXAMPLES / "eightbar.toml")
    th = np.radians(out["inputs"]["crank.angle"])
    start = {k: np.array(v, float) for k, v in sc["guess"].items()}
    branch, ratio = track([eightbar_assemblies(a) for a in th], start)
    assert ratio.max() < 0.2
    size = kincas.cli.scene.load(EXAMPLES / "eightbar.toml").mechanism.size()
    for p in ("R", "S", "G"):
        for c, i in (("x", 0), ("y", 1)):
            got = np.array(out["values"][f"{p}.{c}"])
            assert np.abs(got - [b[p][i] for b in branch]).max() <= POSITION_TOL * size, p + c
    for link in ("lever", "floater"):
        err = np.angle(np.exp(1j * (np.radians(out["values"][f"{link}.angle"]) - [b[link] for b in branch])))
        assert np.abs(err).max() <= ANGLE_TOL, link


@pytest.mark.parametrize("crank_deg", [0, 200])
def test_eightbar_modes_are_all_the_assemblies(crank_deg):
    m = kincas.cli.scene.load(EXAMPLES / "eightbar.toml").mechanism
    a = math.radians(crank_deg)
    found = eightbar_assemblies(a, 200_001)
    assert len(found) >= 2
    match(find_modes(m, {"crank.angle": a}), found, m.size(), ["P", "Q", "R", "S", "H", "G"])
