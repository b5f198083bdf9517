"""kincas's own methods and settings, each as a timed tool, through its public API only.

- `sweep[...]`: one `kincas.sweep` call for the whole sweep, with each option set that this
  kincas accepts (`method`, `compile` or `jit`; an option its `sweep` does not have is
  reported as missing, not faked);
- `solve per pose`: one `kincas.solve` call per pose, its guess the previous pose's points;
- `newton per pose, tol T`: `kincas.compile(m).newton` from the previous pose's unknowns,
  velocities for all poses in one `model.quantities` call at the end; the tolerance is
  kincas's module setting `kincas.core.numeric.TOL` (Newton's target residual), set for the run;
- `IPOPT per pose`: `model.nearest_assembly` (IPOPT, then a Newton polish) targeting the
  previous pose's points; slow, so it runs on every STRIDE-th pose only.

>>> import cases
>>> r = prepare_method(cases.fourbar(8), "newton per pose, tol 1e-13")()
>>> bool(r.ok.all()), r.P["B"].shape
(True, (8, 2))
"""
from __future__ import annotations

import contextlib
import inspect

import numpy as np

from . import Run

IPOPT_STRIDE = 8
TOLS = (1e-6, 1e-9, 1e-13)


def sweep_variants() -> tuple[list, list]:
    """([(label, kwargs for kincas.sweep)] this kincas takes, [(label, why not)]): the default,
    then `method` = "careful" and "fast", and the fast method with its compile switch on and
    off (named `compile` or `jit`), each only if this kincas's `sweep` has the option."""
    import kincas
    params = inspect.signature(kincas.sweep).parameters
    ok, missing = [("sweep (default)", {})], []
    if "method" not in params:
        missing.append(("sweep, method=careful / fast", "kincas.sweep has no `method` option"))
        return ok, missing
    ok += [("sweep, method=careful", {"method": "careful"}), ("sweep, method=fast", {"method": "fast"})]
    switch = next((k for k in ("compile", "jit") if k in params), None)
    if switch is None:
        missing.append(("sweep, method=fast, compiled / not", "kincas.sweep has no `compile` or `jit` option"))
    else:
        ok += [(f"sweep, method=fast, {switch}={v}", {"method": "fast", switch: v}) for v in (True, False)]
    return ok, missing


def methods() -> tuple[list[str], list]:
    """Labels of every kincas method to time here, and the ones this kincas lacks."""
    ok, missing = sweep_variants()
    labels = [lb for lb, _ in ok] + ["solve per pose"]
    labels += [f"newton per pose, tol {t:g}" for t in TOLS] + ["IPOPT per pose"]
    return labels, missing


@contextlib.contextmanager
def newton_tolerance(tol):
    import importlib
    ks = importlib.import_module("kincas.core.numeric")  # where Newton reads its target
    old = ks.TOL
    ks.TOL = tol
    try:
        yield
    finally:
        ks.TOL = old


def _pairs(x, y):
    """(N, 2) from two columns (np.stack's own checks cost ~10 us a call: a short sweep's
    table of results would cost more than kincas's solve of it)."""
    out = np.empty((len(x), 2))
    out[:, 0], out[:, 1] = x, y
    return out


def _result(case, values, ok):
    P = {p: _pairs(values[f"{p}.x"], values[f"{p}.y"]) for p in case.outputs}
    V = {p: _pairs(values[f"{p}.vx"], values[f"{p}.vy"]) for p in case.outputs}
    return Run(P, V, np.asarray(ok, dtype=bool))


def prepare_method(case, label):
    """A `run()` for one kincas method on `case` (raises if this kincas cannot do it)."""
    import kincas
    from cases import kincas_report, to_kincas

    m = to_kincas(case)
    report = kincas_report(case)
    theta, om = case.theta, case.omega
    if label.startswith("sweep"):
        kw = dict(sweep_variants()[0])[label]

        def run():
            sw = kincas.sweep(m, {"crank.angle": theta}, rates={"crank.angle": om}, report=report, **kw)
            return _result(case, sw.values, sw.ok)
        return run
    if label == "solve per pose":
        pts = [f"{p}.{c}" for p in m.moving_points for c in "xy"]
        rep = report + [n for n in pts if n not in report]

        def run():
            vals = {n: np.full(len(theta), np.nan) for n in rep}
            ok, guess = np.zeros(len(theta), dtype=bool), None
            for k, t in enumerate(theta):
                pose = kincas.solve(m, {"crank.angle": t}, rates={"crank.angle": om}, report=rep, guess=guess)
                if pose.ok:
                    ok[k] = True
                    for n in rep:
                        vals[n][k] = pose[n]
                    guess = {p: (pose[f"{p}.x"], pose[f"{p}.y"]) for p in m.moving_points}
            return _result(case, vals, ok)
        return run
    model = kincas.compile(m)
    p = np.array([v for _, v in m.parameters], dtype=float)
    L = m.size()
    U = theta.reshape(-1, 1)
    q_start = model.initial_q(U[0], p, dict(m.guess), L)
    names = list(m.moving_points)

    def finish(Q, ok):
        vals = model.quantities(report, Q[ok], U[ok], p, np.full((ok.sum(), 1), om), np.zeros((ok.sum(), 1)))
        out = {n: np.full(len(theta), np.nan) for n in report}
        for i, n in enumerate(report):
            out[n][ok] = vals[i]
        return _result(case, out, ok)

    if label.startswith("newton per pose"):
        tol = float(label.rsplit(" ", 1)[1])

        def run():
            Q, ok, q = np.full((len(theta), model.nq), np.nan), np.zeros(len(theta), dtype=bool), q_start
            with newton_tolerance(tol):
                for k in range(len(theta)):
                    sol = model.newton(q, U[k], p, L)
                    if sol.ok:
                        Q[k], ok[k], q = sol.q, True, sol.q
            return finish(Q, ok)
        return run
    if label == "IPOPT per pose":
        def run():
            Q, ok = np.full((len(theta), model.nq), np.nan), np.zeros(len(theta), dtype=bool)
            q, u_last = q_start, U[0]
            targets = {k: np.asarray(v, dtype=float) for k, v in m.guess}
            for k in range(len(theta)):
                sol = model.nearest_assembly(q, U[k], p, targets, L)
                if sol.ok:
                    Q[k], ok[k], q, u_last = sol.q, True, sol.q, U[k]
                    pts = model.points(q, u_last, p)
                    targets = {nm: pts[:, j] for j, nm in enumerate(names)}
            return finish(Q, ok)
        return run
    raise KeyError(label)


def stride(label) -> int:
    """Every how many poses of the sweep a method is run on (1: all)."""
    return IPOPT_STRIDE if label == "IPOPT per pose" else 1
