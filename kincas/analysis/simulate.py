"""Forward dynamics: the motion of a mechanism's free inputs under loads, gravity and inertia.

The equations of motion M(u) u_f'' = -h(u, u', t) come from kincas's efforts
(kincas/core/motion.py); CasADi's CVODES integrates them, with q(u) solved by Newton at
every evaluation. The output times are equally spaced; the integration is checked at each
for the events that stop it (a singular position or a limit of a free input, where g_q is
singular; a cam follower whose contact force falls to zero), and an event is located in time
by bisection with the integrator itself (to EVENT_TIME of the duration).

>>> import numpy as np, kincas
>>> m = kincas.Mechanism(ground={"O": (0, 0)},
...     links=[kincas.Link.bar("bob", "O", "A", 1.0, mass=1.0, cg=(1.0, 0))],
...     inputs=[kincas.Input.angle("bob")], gravity=(0, -9.81))
>>> r = simulate(m, 1.0, 11, initial={"bob.angle": -np.pi / 2 + 0.01}, report=["A.x"])
>>> r.ok, len(r.time), bool(abs(r.inputs["bob.angle"][-1] + np.pi / 2) < 0.0101)
(True, 11, True)
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field

import numpy as np

from ..core.motion import Motion
from ..core.motion_loads import LoadExpression
from ..core.numeric import model_of
from ..core.tolerances import EVENT_TIME, SIM_ATOL, SIM_CLASSIFY, SIM_MAX_STEPS, SIM_RTOL, SIM_SINGULAR
from ..errors import ModelError
from ..model.mechanism import Link, Mechanism
from ..result_base import Result
from ..model.names import is_angle_name

FLYWHEEL = "_flywheel_inertia"  # the hidden parameter carrying the flywheel link's inertia


def rate_name(key: str) -> str:
    """The name of an input's rate: `L.omega` for an angle, `S.v` for a slide, `d(p)/dt`.

    >>> rate_name("crank.angle"), rate_name("guide.s"), rate_name("a1"), rate_name("x.angle2")
    ('crank.omega', 'guide.v', 'd(a1)/dt', 'x.omega2')
    """
    obj, _, attr = key.rpartition(".")
    if is_angle_name(key):  # J.angle1 -> J.omega1
        return f"{obj}.omega{attr[5:]}"
    if obj and attr in ("s", "s1", "s2"):
        return f"{obj}.v{attr[1:]}"
    return f"d({key})/dt"


@dataclass(repr=False)
class Simulation(Result):
    """The motion over time: `time`, the inputs (continuous) and their rates, the reported
    quantities, a status per output time ("ok", or "not reached" after an early stop) and
    the events that stopped it (each with `time` and `reason`).

    Examples
    --------
    >>> s = Simulation(np.array([0.0, 1.0]), {"x.s": np.zeros(2)}, {"x.s": np.ones(2)},
    ...                {"x.s": np.zeros(2)}, {}, np.array(["ok", "ok"], dtype=object), [])
    >>> s.ok, s.summary()
    (True, '2 times, 2 reached; inputs x.s')
    """

    time: np.ndarray
    inputs: dict
    rates: dict
    accelerations: dict
    values: dict
    status: np.ndarray
    events: list = field(default_factory=list)
    q: np.ndarray | None = None
    info: dict = field(default_factory=dict)

    @property
    def ok(self) -> bool:
        """Whether the whole duration was integrated."""
        return bool(np.all(self.status == "ok"))

    def summary(self) -> str:
        n, good = len(self.time), int(np.sum(self.status == "ok"))
        ev = f"; stopped at t = {self.events[0]['time']:.6g}: {self.events[0]['reason']}" if self.events else ""
        return f"{n} times, {good} reached; inputs {', '.join(self.inputs)}{ev}"

    def columns(self) -> dict:
        """Every series by name: inputs, their rates (`rate_name`), the reported quantities."""
        out = dict(self.inputs)
        out.update({rate_name(k): v for k, v in self.rates.items()})
        out.update({k: v for k, v in self.values.items() if k not in out})
        return out

    def to_pandas(self, length: str = "", angle: str = "rad"):
        """A DataFrame indexed by `time`: inputs, rates, quantities, status.

        Examples
        --------
        >>> s = Simulation(np.array([0.0, 1.0]), {"x.s": np.zeros(2)}, {"x.s": np.ones(2)},
        ...                {"x.s": np.zeros(2)}, {}, np.array(["ok", "ok"], dtype=object), [])
        >>> list(s.to_pandas().columns), s.to_pandas().index.name
        (['x.s', 'x.v', 'status'], 'time')
        """
        from ..frames import in_angle, require, unit_of
        pd = require("pandas")
        cols = {k: np.asarray(v, float) for k, v in self.columns().items()}
        df = pd.DataFrame({**cols, "status": self.status.astype(str)},
                          index=pd.Index(np.asarray(self.time, float), name="time"))
        df.attrs["units"] = {k: unit_of(k, length) for k in cols}
        return in_angle(df, angle)

    def to_xarray(self, length: str = "", angle: str = "rad"):
        """A Dataset along the dimension `time`.

        Examples
        --------
        >>> s = Simulation(np.array([0.0, 1.0]), {"x.s": np.zeros(2)}, {"x.s": np.ones(2)},
        ...                {"x.s": np.zeros(2)}, {}, np.array(["ok", "ok"], dtype=object), [])
        >>> s.to_xarray()["x.v"].dims
        ('time',)
        """
        from ..frames import in_angle, require, unit_of
        xr = require("xarray")
        data = {k: ("time", np.asarray(v, float), {"units": unit_of(k, length)})
                for k, v in self.columns().items()}
        data["status"] = ("time", self.status.astype(str))
        return in_angle(xr.Dataset(data, coords={"time": np.asarray(self.time, float)}), angle)

    def sweep(self):
        """The motion as a `Sweep` whose first input is the time `t` (the abscissa of the
        solve command's tables, plots and pictures)."""
        from ..results import Sweep
        n = len(self.time)
        ins = {"t": np.asarray(self.time, float), **self.inputs}
        rates = {"t": np.ones(n), **self.rates}
        accs = {"t": np.zeros(n), **self.accelerations}
        q = self.q if self.q is not None else np.full((n, 0), np.nan)
        values = {rate_name(k): v for k, v in self.rates.items()}  # the rates: columns too
        values.update(self.values)
        return Sweep(ins, rates, accs, self.status.copy(), [None] * n, values, q,
                     np.zeros(n), np.zeros(n, int), [], 1.0, [], {})


# --- the mechanism the equations are written on ---


def with_flywheel(m: Mechanism, flywheel) -> Mechanism:
    """`m` with its flywheel link's inertia a parameter (FLYWHEEL): the link's own inertia
    plus the flywheel's (about the link's axis; its centre on the pivot adds no mass term)."""
    link, J = flywheel
    lk = m.link(link)
    i = lk.inertial
    params = dict(m.parameters)
    params[FLYWHEEL] = float(m.value(i.inertia)) + float(J)
    new = Link(lk.name, lk.points, lk.two_point, mass=i.mass, inertia=FLYWHEEL, cg=i.cg)
    return dataclasses.replace(m, parameters=params,
                               links=[new if x.name == link else x for x in m.links])


def simulate(mechanism: Mechanism, duration: float, steps: int = 101, *, free=None, initial=None,
             rates=None, accelerations=None, expressions=None, data=None, flywheel=None,
             tolerance: float = SIM_RTOL, report=None, angle: float = 1.0, guess=None) -> Simulation:
    """Integrate the motion of the free inputs from rest or from given rates.

    Parameters
    ----------
    mechanism : Mechanism
    duration : float
        Time integrated (the time unit of the loads and rates).
    steps : int
        Output times, equally spaced, t = 0 and t = duration included.
    free : list of str, optional
        The free inputs' keys (default: every input). The others are held to
        u0 + rate t + acceleration t^2 / 2.
    initial, rates, accelerations : dict, optional
        Input key -> value at t = 0 (default 0), rate at t = 0 (default 0), acceleration of
        a held input.
    expressions : dict, optional
        Parameter name -> expression of the state and time (kincas/core/motion_loads.py):
        the parameter (a load's component) takes the expression's value at every instant.
    data : dict, optional
        Named lists for `interp(x, xs, ys)` in the expressions.
    flywheel : (str, float), optional
        A link and the inertia added about its axis.
    tolerance : float
        The integrator's relative tolerance.
    report : list of str, optional
        Quantities at the output times (kincas's names: efforts included).
    angle : float
        The expressions' angle unit in radians (pi / 180 for degrees).
    guess : dict, optional
        Points' guessed positions at t = 0 (they pick the assembly).

    Returns
    -------
    Simulation

    Examples
    --------
    >>> import kincas
    >>> m = kincas.Mechanism(ground={"O": (0, 0)}, inputs=[kincas.Input.angle("wheel")],
    ...     links=[kincas.Link.bar("wheel", "O", "A", 1.0, inertia=2.0)],
    ...     parameters={"T": 0.0}, loads=[kincas.Load.torque("wheel", "T")])
    >>> r = simulate(m, 2.0, 3, expressions={"T": "4"})     # alpha = T / J = 2
    >>> [round(float(x), 9) for x in r.inputs["wheel.angle"]]
    [0.0, 1.0, 4.0]
    """
    setup = _Setup(mechanism, free, expressions, data, flywheel, angle)
    return setup.run(duration, steps, initial or {}, rates or {}, accelerations or {}, tolerance,
                     report, guess)


class _Setup:
    """The model, the equations of motion and the integrators of one simulation's structure."""

    def __init__(self, mechanism, free, expressions, data, flywheel, angle):
        m = with_flywheel(mechanism, flywheel) if flywheel else mechanism
        keys = [i.key for i in m.inputs]
        self.free = list(free) if free is not None else keys
        bad = [k for k in self.free if k not in keys]
        if bad:
            raise ModelError(f"free: unknown input(s) {bad} (inputs: {keys})")
        data = dict(data or {})
        exprs = {}
        for name, e in (expressions or {}).items():
            exprs[name] = e if isinstance(e, LoadExpression) else LoadExpression(e, f"expression of {name}", data)
        self.m, self.model, self.angle = m, model_of(m), angle
        self.exprs = exprs
        cams = [c.name for c in m.cams if c.follower[0] in ("knife", "roller")]
        key = ("motion", tuple(self.free), tuple((k, e.text) for k, e in exprs.items()),
               tuple((k, tuple(v)) for k, v in sorted(data.items())), angle, tuple(cams))
        self.motion = self.model.memo(key, lambda: Motion(self.model, self.free, exprs, angle, cams))
        self.cams = cams

    def run(self, duration, steps, initial, rates, accs, tol, report, guess):
        from .sweeps import sweep
        if not (isinstance(steps, int) and steps >= 2) or not (duration > 0 and math.isfinite(duration)):
            raise ModelError(f"[simulate]: expected duration > 0 and steps >= 2, got {duration}, {steps}")
        if not (0 < tol < 1):
            raise ModelError(f"[simulate] tolerance: expected a number in (0, 1), got {tol}")
        m, mo, model = self.m, self.motion, self.model
        keys = [i.key for i in m.inputs]
        u0 = np.array([float(initial.get(k, 0.0)) for k in keys])
        v0 = np.array([float(rates.get(k, 0.0)) for k in keys])
        a0 = np.array([float(accs.get(k, 0.0)) for k in keys])
        p = np.array([v for _, v in m.parameters], float)
        held = mo.held
        par = np.concatenate([p, u0[held], v0[held], a0[held]])
        times = np.linspace(0.0, float(duration), steps)
        first = sweep(m, {k: [u0[j]] for j, k in enumerate(keys)}, report=[], guess=guess)
        nq, nf = model.nq, len(mo.free)
        X = np.full((steps, nq + 2 * nf), np.nan)
        events = []
        if not first.ok[0]:
            events.append({"time": 0.0, "reason": f"no assembly at t = 0 ({first.status[0]})"})
        else:
            X[0] = np.concatenate([first.q[0], u0[mo.free], v0[mo.free]])
            self._march(X, times, par, tol, events)
        return self._result(X, times, par, u0, v0, a0, events, report)

    def _march(self, X, times, par, tol, events):
        """Fill X row by row (chunks that double while they succeed, halve when not); stop at
        the first event, located by bisection."""
        n, k, size = len(times), 0, 16
        h = times[1] - times[0]
        try:
            sign = self._events(X[:1], times[:1], par, None)[1]
        except RuntimeError:
            sign = None
        while k < n - 1:
            size = min(size, n - 1 - k)
            try:
                xs = self.motion.integrate(X[k], par, times[k], h, size, tol)
                bad, last = self._events(xs, times[k + 1:k + 1 + size], par, sign)
            except RuntimeError:  # the integrator, or Newton at an output state
                xs, bad, last = None, (0, "the integration failed"), sign
                if size > 1:
                    size //= 2
                    continue
            j = size if bad is None else bad[0]
            if j:
                X[k + 1:k + 1 + j] = xs[:j]
            k += j
            if bad is not None:
                events.append(self._locate(X[k], times[k], times[k + 1], par, tol, bad[1], sign))
                return
            sign, size = last, size * 2

    def _events(self, xs, ts, par, sign):
        """((index, reason) of the first state of `xs` where the motion must stop, or None;
        the sign of det g_q at the last state; RuntimeError where Newton finds no q, which the
        march treats as a failed integration). Passing a limit of a free input (a dead
        centre), q moves to the other assembly: det g_q changes sign, as in a sweep."""
        q, acc, C, J, _ = self.motion.post(xs, ts, par)  # RuntimeError where Newton finds no q
        nq, n = self.model.nq, len(ts)
        bad = np.zeros(n, bool)
        why = np.full(n, "", dtype=object)
        if self.cams:
            lost = np.any(C <= 0, axis=0)
            why[lost] = [f"contact lost on cam {self.cams[int(np.argmax(C[:, i] <= 0))]} (its contact "
                         f"force reached zero)" for i in np.flatnonzero(lost)]
            bad |= lost
        sing = ~np.all(np.isfinite(acc), axis=0)
        signs = np.zeros(n)
        if nq:  # all states at once: (n, ng, nq) Jacobians, columns scaled
            Js = J.T.reshape(n, nq, -1).transpose(0, 2, 1) * self.model.column_scale(self.m.size())
            sv = np.linalg.svd(Js, compute_uv=False)
            sing |= ~np.all(np.isfinite(sv), axis=1) | (sv[:, -1] <= SIM_SINGULAR * sv[:, 0])
            if Js.shape[1] == nq:
                signs = np.sign(np.linalg.det(Js))
                prev = np.concatenate([[sign if sign is not None else signs[0]], signs[:-1]])
                sing |= signs != prev
        why[sing & ~bad] = self._singular_reason()
        bad |= sing
        if bad.any():
            i = int(np.argmax(bad))
            return (i, why[i]), sign
        return None, (signs[-1] if nq else sign)

    def _singular_reason(self) -> str:
        free = ", ".join(self.free)
        return f"a singular position or a limit of {free} (g_q singular)"

    def _kind(self, x, t, par) -> str:
        """At the last state before a singular position: a limit of the free inputs when
        (g_q | g_u) keeps its rank there (the inputs cannot go further: a dead centre), a
        singular position (a change point) when it loses rank with g_q."""
        try:
            _, _, _, J, Ju = self.motion.post(x[None, :], np.array([t]), par)
        except RuntimeError:
            return self._singular_reason()
        nq, free, L = self.model.nq, ", ".join(self.free), self.m.size()
        if not nq:
            return self._singular_reason()
        Jq = J[:, 0].reshape(-1, nq, order="F")
        # columns O(1) at any size: an angle's column is a length (over L), a length's a ratio
        col = [1 / L if is_angle_name(k) else 1.0 for k in self.free]
        A = np.hstack([Jq * self.model.column_scale(L), Ju[:, 0].reshape(Jq.shape[0], -1, order="F") * col])
        # near a limit g_q's smallest singular value goes like the square root of the distance
        # and (g_q | g_u)'s stays finite; near a change point both go like the distance
        sq, sa = (np.linalg.svd(B, compute_uv=False) for B in (A[:, :nq], A))
        if sa[min(A.shape) - 1] > SIM_CLASSIFY * sq[-1]:
            return f"a limit of {free} (g_q singular: it can go no further this way)"
        return f"a singular position (g_q and (g_q | g_u) singular: a change point of {free})"

    def _locate(self, x, t_lo, t_hi, par, tol, reason, sign):
        """The event's time, by bisection between a good state at t_lo and a bad one at t_hi."""
        span = t_hi - t_lo
        while t_hi - t_lo > EVENT_TIME * max(span, abs(t_hi)):
            mid = 0.5 * (t_lo + t_hi)
            try:
                xm = self.motion.integrate(x, par, t_lo, mid - t_lo, 1, tol)[0]
                bad, s_mid = self._events(xm[None, :], np.array([mid]), par, sign)
            except RuntimeError:
                bad = (0, reason)  # (the event's own reason, if a state says it, wins below)
            if bad is None:
                x, t_lo, sign = xm, mid, s_mid
            else:
                t_hi, reason = mid, bad[1] if reason == "the integration failed" else reason
        if reason == self._singular_reason():
            reason = self._kind(x, t_lo, par)
        return {"time": float(t_lo), "reason": reason, "kind": "stop"}

    # --- the outputs ---
    def _result(self, X, times, par, u0, v0, a0, events, report):
        m, mo, model = self.m, self.motion, self.model
        keys = [i.key for i in m.inputs]
        n, nq, nf, nu = len(times), model.nq, len(mo.free), len(keys)
        ok = np.all(np.isfinite(X), axis=1)
        U, Ud, Udd = np.tile(u0, (n, 1)), np.tile(v0, (n, 1)), np.tile(a0, (n, 1))
        h = mo.held
        U[:, h] = u0[h] + v0[h] * times[:, None] + a0[h] * times[:, None] ** 2 / 2
        Ud[:, h] = v0[h] + a0[h] * times[:, None]
        U[:, mo.free], Ud[:, mo.free] = X[:, nq:nq + nf], X[:, nq + nf:]
        Q = np.full((n, nq), np.nan)
        idx = np.flatnonzero(ok)
        P = np.tile(par[:len(m.parameters)][:, None], n)
        if idx.size:
            q, acc, _, _, _ = mo.post(X[idx], times[idx], par)
            Q[idx] = q.T
            Udd[np.ix_(idx, mo.free)] = acc.T
            P[:, idx] = mo.parameters(q, U[idx].T, Ud[idx].T, times[idx], P[:, idx])
        U[~ok], Ud[~ok], Udd[~ok] = np.nan, np.nan, np.nan
        names = list(report) if report is not None else []
        values = {nm: np.full(n, np.nan) for nm in names}
        if names and idx.size:
            f = model.quantity_function(tuple(names)).map(idx.size)
            got = np.asarray(f(Q[idx].T, U[idx].T, P[:, idx], Ud[idx].T, Udd[idx].T))
            for i, nm in enumerate(names):
                values[nm][idx] = got[i]
        status = np.array(["ok" if o else "not reached" for o in ok], dtype=object)
        sim = Simulation(times, {k: U[:, j] for j, k in enumerate(keys)},
                         {k: Ud[:, j] for j, k in enumerate(keys)},
                         {k: Udd[:, j] for j, k in enumerate(keys)}, values, status, events, Q,
                         {"free": list(self.free), "parameters": P})
        for k in values:  # reported angles wrapped, as a sweep reports them
            if k.endswith((".angle", ".phi")) and not k.startswith("d("):
                from ..results import wrap_angle
                values[k] = wrap_angle(values[k])
        return sim
