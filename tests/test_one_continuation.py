"""One continuation (issue [15]: "continuation four ways"): the careful path of a sweep,
the range of an input, Assur groups carried through a gap and the designs' first poses
continued in the parameters all walk through kincas/analysis/path.py, and every walk ends
with a reason from the same words (`path.STOPS`).

Checked three ways: the source has no predictor-corrector loop (nor a recursive step
halving) outside path.py; each of the four callers is seen running through
`path.follow_all`; and the stop reasons of a walk in the inputs and of one in the
parameters are the same words, the poses reached checked against the circle intersection.
"""
from __future__ import annotations

import ast
import sys

import numpy as np
import pytest

from conftest import ROOT

import kincas
from kincas.analysis import path

PKG = ROOT / "kincas"
# compiled or JAX code paths (and their numpy twin): another job, with the kernel's own tests
KERNELS = {"kernel.py", "group_kernel.py", "fast.py", "fast_run.py", "fast_vm.py", "designs_kernel.py",
           "jax_backend.py", "designs_jax.py"}
# predictor-corrector loops that are not a continuation, with the reason
NOT_CONTINUATIONS = {
    ("kincas/analysis/design_job.py", "_batched_pass"):
        "the compiled fast pass's numpy twin: accepts by the kernel's tests, so both agree",
}
PREDICTION = ("pred", "zp")  # names of a prediction
TANGENTS = {"Gp"}  # g_p: a tangent in the parameters (a call named *tangent*: in the inputs)
CORRECTORS = ("newton", "_correct", "derivatives")


def _called(node) -> str:
    f = node.func
    return f.attr if isinstance(f, ast.Attribute) else f.id if isinstance(f, ast.Name) else ""


def _body(node):
    """The nodes of `node`, not entering nested functions (a step function is not a loop)."""
    todo = list(ast.iter_child_nodes(node))
    while todo:
        n = todo.pop()
        if isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda)):
            continue
        yield n
        todo.extend(ast.iter_child_nodes(n))


def continuation_loops(source: str) -> list[str]:
    """Functions that walk a path themselves: a loop that predicts (assigns a name starting
    with `pred` or `zp`, or uses a tangent: g_p, a call named *tangent*) and corrects (calls a Newton, a corrector or the batched
    derivatives), or a function that calls itself on a midpoint (recursive step halving)."""
    out = []
    for fn in ast.walk(ast.parse(source)):
        if not isinstance(fn, (ast.FunctionDef, ast.AsyncFunctionDef)):
            continue
        for loop in (n for n in _body(fn) if isinstance(n, (ast.For, ast.While))):
            inner = [loop, *_body(loop)]
            predicts = any(isinstance(n, ast.Assign) and any(isinstance(t, ast.Name) and t.id.startswith(PREDICTION)
                                                             for t in n.targets) for n in inner) \
                or any(isinstance(n, ast.Name) and n.id in TANGENTS or isinstance(n, ast.Call) and "tangent" in _called(n)
                       for n in inner)
            corrects = any(isinstance(n, ast.Call) and any(c in _called(n) for c in CORRECTORS) for n in inner)
            if predicts and corrects:
                out.append(fn.name)
                break
        calls = [n for n in _body(fn) if isinstance(n, ast.Call)]
        if any(_called(n) == fn.name for n in calls) and "0.5 *" in ast.unparse(fn):
            out.append(fn.name)
    return sorted(set(out))


def test_no_continuation_outside_path():
    bad = []
    for p in sorted((PKG / "core").glob("*.py")) + sorted((PKG / "analysis").glob("*.py")):
        if p.name in KERNELS or p == PKG / "analysis" / "path.py":
            continue
        rel = str(p.relative_to(ROOT))
        bad += [f"{rel}: {f}" for f in continuation_loops(p.read_text(encoding="utf-8"))
                if (rel, f) not in NOT_CONTINUATIONS]
    assert not bad, "a path walked outside kincas/analysis/path.py:\n" + "\n".join(bad)


def test_the_scan_finds_the_old_continuations():
    """The four ways there were, in miniature: each is found (the scan can fail)."""
    recursive = ("def _continue(q0, u0, u1, depth):\n    sol = newton(q0 + t, u1)\n"
                 "    if sol.ok or depth == 0:\n        return sol\n    um = 0.5 * (u0 + u1)\n"
                 "    mid = _continue(q0, u0, um, depth - 1)\n    return _continue(mid, um, u1, depth - 1)\n")
    arclength = ("def _follow(z, t, h):\n    for _ in range(99):\n        zp = z + h * t\n"
                 "        zn = _correct(zp, t)\n        if zn is None:\n            h /= 2\n")
    batched = ("def first(q, P):\n    for i in range(9):\n        q = q - solve(J, Gp @ dp)\n"
               "        g, J, _, _ = ev.derivatives(q, u, P)\n")
    assert continuation_loops(recursive) == ["_continue"]
    assert continuation_loops(arclength) == ["_follow"]
    assert continuation_loops(batched) == ["first"]
    step_only = "def walk():\n    def step(w):\n        pred = w.at + 1\n        return newton(pred)\n    return follow(step)\n"
    assert continuation_loops(step_only) == []


def triple_rocker(b=1.9, params=None):
    return kincas.Mechanism(parameters=params or {}, ground={"A": (0, 0), "D": (4, 0)},
                            links=[kincas.Link.bar("crank", "A", "B", 1), kincas.Link.bar("coupler", "B", "C", b),
                                   kincas.Link.bar("rocker", "D", "C", 3)],
                            inputs=[kincas.Input.angle("crank")], guess={"C": (3.2, 2.5)})


def circle_c(theta, b, sign=+1):
    """C, where the circles about B (radius b) and D (radius 3) meet, on the side `sign` of B->D."""
    B = np.array([np.cos(theta), np.sin(theta)])
    e = np.array([4.0, 0.0]) - B
    r = np.hypot(*e)
    x = (b * b - 9 + r * r) / (2 * r)
    h = np.sqrt(b * b - x * x)
    e /= r
    return B + x * e + sign * h * np.array([-e[1], e[0]])


def test_every_continuation_walks_through_path():
    """The careful path, the range of an input, a group carried through a gap and the
    designs' first poses: each is seen calling path.follow_all (by whatever name it was
    imported), from the function that owns it."""
    from kincas.analysis.singular import input_range
    from kincas.analysis.resume import carry_groups
    seen = set()
    code = path.follow_all.__code__

    def watch(frame, event, arg):
        if event == "call" and frame.f_code is code:
            f = frame.f_back
            if f.f_code is path.follow.__code__:
                f = f.f_back
            seen.add(f.f_code.co_name)
    m = triple_rocker()
    U = np.radians([[140.0], [180.0], [220.0]])
    q0 = kincas.sweep(m, {"crank.angle": U[:1, 0]}).q[0]
    sys.setprofile(watch)
    try:
        kincas.sweep(m, {"crank.angle": np.radians(np.arange(100.0, 161.0, 4.0))}, method="careful")
        input_range(m, {"crank.angle": 0.5})
        carry_groups(kincas.model_of(m), U, np.zeros(0), m.size(), 0, q0, 2, [0])
        md = triple_rocker("b", {"b": 3.5})
        kincas.sweep_designs(md, {"b": [3.4, 3.6]}, {"crank.angle": [0.0, 0.1]}, compile=False, workers=1)
    finally:
        sys.setprofile(None)
    assert {"walk_inputs", "_follow", "_carry", "walk_parameters"} <= seen, seen


def test_a_walk_in_the_parameters_stops_for_the_reasons_a_walk_in_the_inputs_does():
    """Continued in the inputs into the triple rocker's gap (no assembly from 151.2 deg) and
    in the parameters to a coupler too short to close the loop: both walks stop "not
    converged", a key of path.STOPS; where they reach their end, C is on the circle
    intersection of the branch they started on."""
    from kincas.analysis.continuation import walk_inputs, walk_parameters
    from kincas.core.assembly import modes
    m = triple_rocker()
    model, L, p = kincas.model_of(m), m.size(), np.zeros(0)
    u0 = np.array([np.radians(140.0)])
    q0 = kincas.sweep(m, {"crank.angle": u0}).q[0]
    gone = walk_inputs(model, q0, u0, np.radians([180.0]), p, L, depth=8)
    there = walk_inputs(model, q0, u0, np.radians([150.0]), p, L, depth=8)
    assert gone.reason == "not converged" and gone.reason in path.STOPS and not gone.ok
    assert gone.reach and gone.reach[-1][1][0] < np.radians(151.2)  # as far as the branch goes
    assert there.reason == "reached" and there.ok
    c = model.points(there.at.q, np.radians([150.0]), p)[:, list(m.moving_points).index("C")]
    assert np.abs(c - circle_c(np.radians(150.0), 1.9)).max() <= 1e-12 * L

    md = triple_rocker("b", {"b": 3.5})
    model, L, u = kincas.model_of(md), md.size(), np.array([0.5])
    q0 = kincas.sweep(md, {"crank.angle": u}).q[0]
    p0 = np.array([3.5])
    sign0 = modes(model, model.jac(q0, u, p0), L)[0]
    P = np.array([[3.0], [0.1]])  # |BD| = 3.159 at 0.5 rad: a coupler of 0.1 and the rocker of 3 fall short
    walks = walk_parameters(model, u, q0, p0, P, np.full(2, L), sign0)
    assert [w.reason for w in walks] == ["reached", "not converged"]
    assert all(w.reason in path.STOPS for w in walks)
    c = model.points(walks[0].at, u, P[0])[:, list(md.moving_points).index("C")]
    assert np.abs(c - circle_c(0.5, 3.0)).max() <= 1e-12 * L


@pytest.mark.parametrize("depth", [0, 1, 3])
def test_bisect_walks_as_the_recursive_halving_did(depth):
    """Bisect is the recursion it replaced, step for step: the points tried, in order, and
    the pose each half is predicted from (for the secant), on a step that is refused while
    longer than 1/4 of the path, against that recursion written out here."""
    def recursive(a, b, d, before, log):
        log.append((a, b, before))
        if b - a <= 0.25:
            return True
        if d == 0:
            return False
        mid = 0.5 * (a + b)
        return recursive(a, mid, d - 1, before, log) and recursive(mid, b, d - 1, a, log)
    expected = []
    ok = recursive(0.0, 1.0, depth, -1.0, expected)
    got = []

    def step(w):
        got.append((w.where, w.target, w.before[1]))
        return w.target, None if w.target - w.where <= 0.25 else "slow"
    w = path.follow(0.0, 0.0, path.Bisect(1.0, depth, (None, -1.0)), step)
    assert got == expected and w.ok == ok
