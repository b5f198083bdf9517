"""`kincas flywheel SCENE.toml --fluctuation Cs` and `kincas simulate SCENE.toml --steady`.

`--steady`: the periodic steady state of the scene's machine (kincas/analysis/steady.py):
the cycle, its time, the mean speed and the coefficient of speed fluctuation
(w_max - w_min) / w_mean. `kincas flywheel`: the smallest inertia added on the
`[simulate].flywheel` link that keeps that coefficient at or below Cs, beside the energy
method's estimate dE / (Cs w_mean^2). Speeds are printed in the scene's units (angle/time).
"""
from __future__ import annotations

import json
import math
import sys

import numpy as np

from ..errors import OutputError, SceneError
from .common import EXIT_OK
from .scene import load
from .scene_simulate import arguments_of


def cli_arguments(parser) -> None:
    """Arguments of `kincas flywheel`."""
    parser.add_argument("scene", help="the scene file (TOML) with a free crank and [simulate].flywheel")
    parser.add_argument("--fluctuation", type=float, required=True, metavar="Cs",
                        help="the coefficient of speed fluctuation (w_max - w_min) / w_mean to keep")
    parser.add_argument("--json", action="store_true", help="print inertia, estimate, fluctuation, w_mean as JSON")


class _Machine:
    """A scene's free crank at its steady state, for any added flywheel inertia."""

    def __init__(self, sc, need_flywheel=False):
        from ..analysis.simulate import FLYWHEEL, _Setup
        from ..analysis.steady import Shooting
        from ..analysis.sweeps import sweep
        kw = arguments_of(sc)
        fw = kw["flywheel"]
        if need_flywheel and fw is None:
            raise SceneError("[simulate] flywheel: missing (kincas flywheel sizes the inertia on "
                             "{ link = \"NAME\", inertia = J })")
        self.sc, self.fw = sc, fw
        setup = _Setup(sc.mechanism, kw["free"], kw["expressions"], kw["data"],
                       (fw[0], 0.0) if fw else None, kw["angle"])
        self.shoot = Shooting(setup)
        key = setup.free[0]
        self.th0, self.w0 = kw["initial"][key], kw["rates"][key]
        if self.w0 == 0:  # from rest: shoot from where the [simulate] run-up ends
            sim = sc.study.simulation
            r = setup.run(sim["duration"], sim["steps"] or 101, kw["initial"], kw["rates"], kw["accelerations"],
                          kw.get("tolerance", 1e-10), [], None)
            if not r.ok or r.rates[key][-1] == 0:
                raise SceneError(f"[[inputs]] {key}: rate: the machine does not run up from rest "
                                 f"over [simulate] duration; give the rate it runs at, roughly")
            self.th0, self.w0 = float(r.inputs[key][-1]), float(r.rates[key][-1])
        first = sweep(setup.m, {key: [self.th0]}, report=[])
        if not first.ok[0]:
            raise SceneError(f"[[inputs]] {key}: no assembly at value {self.th0}")
        self.q0, self.tol = first.q[0], kw.get("tolerance", 1e-10)
        self.p = np.array([v for _, v in setup.m.parameters], float)
        names = [k for k, _ in setup.m.parameters]
        self.k = names.index(FLYWHEEL) if fw else None
        self.base = self.p[self.k] if fw else 0.0

    def steady(self, added=None):
        p = self.p.copy()
        if self.k is not None:
            p[self.k] = self.base + (self.fw[1] if added is None else added)
        return self.shoot.steady(self.q0, self.th0, self.w0, p, self.tol), p


def print_steady(sc, args) -> int:
    st, _ = _Machine(sc).steady()
    k = 180 / math.pi if sc.study.deg else 1.0
    doc = {"cycle": st.cycle * k, "period": st.period, "w0": st.w0 * k, "w_mean": st.w_mean * k, "w_max": st.w_max * k,
           "w_min": st.w_min * k, "fluctuation": st.fluctuation}
    if args.json:
        sys.stdout.write(json.dumps(doc) + "\n")
    else:
        u = f"{sc.study.units.get('angle', 'deg')}/{sc.study.units.get('time', 's')}"
        print(f"{sc.study.title or 'kincas simulate --steady'}: periodic steady state")
        print(f"cycle {doc['cycle']:.6g} {sc.study.units.get('angle', 'deg')} in {st.period:.9g} "
              f"{sc.study.units.get('time', 's')}")
        print(f"w_mean {doc['w_mean']:.9g} {u}, w_max {doc['w_max']:.9g}, w_min {doc['w_min']:.9g}")
        print(f"coefficient of speed fluctuation (w_max - w_min) / w_mean = {st.fluctuation:.6g}")
    return EXIT_OK


def size_flywheel(machine, target: float) -> dict:
    """The smallest added inertia with fluctuation <= target (Brent's method on a bracket
    that doubles from the energy method's estimate), and that estimate."""
    from scipy.optimize import brentq
    cs = lambda J: machine.steady(J)[0].fluctuation - target  # noqa: E731
    try:
        st0, _ = machine.steady(0.0)
    except RuntimeError:  # CVODES: the free input's reduced inertia is singular without a flywheel
        raise OutputError("[simulate] flywheel: without an added flywheel the free input has no inertia "
                          "(the flywheel's link and the links it moves are massless), so the search that "
                          "starts from no flywheel cannot run: give that link an inertia of its own") from None
    if st0.fluctuation <= target:
        J = 0.0
    else:
        hi = max(machine.shoot.net_work(machine.q0, machine.th0, st0.w_mean, machine.p)
                 / (target * st0.w_mean ** 2), 1e-12)
        lo = 0.0
        while cs(hi) > 0:
            lo, hi = hi, 2 * hi
            if hi > 1e12:
                raise OutputError("--fluctuation: no flywheel inertia reaches it")
        J = brentq(cs, lo, hi, xtol=1e-12, rtol=1e-9)
        while cs(J) > 0:  # at or below the target: the root's side where it holds
            J += max(1e-9 * J, 1e-15)
    st, p = machine.steady(J)
    dE = machine.shoot.net_work(machine.q0, machine.th0, st.w_mean, p)
    return {"inertia": J, "estimate": dE / (target * st.w_mean ** 2), "fluctuation": st.fluctuation,
            "w_mean": st.w_mean, "energy": dE}


def cli_run(args) -> int:
    if not 0 < args.fluctuation < 1:
        raise OutputError(f"--fluctuation: expected a number in (0, 1), got {args.fluctuation}")
    sc = load(args.scene)
    out = size_flywheel(_Machine(sc, need_flywheel=True), args.fluctuation)
    k = 180 / math.pi if sc.study.deg else 1.0
    doc = {"inertia": out["inertia"], "estimate": out["estimate"], "fluctuation": out["fluctuation"],
           "w_mean": out["w_mean"] * k}
    if args.json:
        sys.stdout.write(json.dumps(doc) + "\n")
    else:
        link = sc.study.simulation["flywheel"][0]
        u = f"{sc.study.units.get('angle', 'deg')}/{sc.study.units.get('time', 's')}"
        print(f"{sc.study.title or 'kincas flywheel'}: flywheel on {link} for Cs <= {args.fluctuation:g}")
        print(f"inertia added {doc['inertia']:.6g} (steady state: Cs = {doc['fluctuation']:.6g}, "
              f"w_mean = {doc['w_mean']:.6g} {u})")
        print(f"energy method: dE / (Cs w_mean^2) = {doc['estimate']:.6g} (dE = {out['energy']:.6g})")
    return EXIT_OK
