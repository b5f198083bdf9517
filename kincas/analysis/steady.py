"""Periodic steady state of a machine driven round by periodic loads, and the flywheel it needs.

One free angle input theta turns round; the loads repeat over a cycle Theta of it (the
period of the `%` in their expressions, else one turn: 720 deg for a four-stroke table).
Over a cycle the motion is integrated with theta as the independent variable,

    dt/dtheta = 1/w,   dq/dtheta = q'/w,   dw/dtheta = theta''/w,

so that the cycle's end is exactly theta0 + Theta. Shooting (secant on w0) makes the speed at
the end of the cycle equal the speed at its start: the periodic steady state. Then
w_mean = Theta / (cycle time), and w_max, w_min are the extremes of the continuous w(theta):
at the samples' extreme, the root of dw/dtheta = 0 is located by the cubic Hermite
interpolant of (w, dw/dtheta) and w is integrated exactly up to it.

The flywheel: Cs(J) = (w_max - w_min)/w_mean falls as the inertia J added on the flywheel
link grows; the smallest J with Cs(J) <= Cs* is found by bracketing and Brent's method,
beside the energy method's estimate dE / (Cs* w_mean^2), dE the largest swing of the work of
the net torque at constant speed, integral of (T(theta) - T_mean) dtheta.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import ModelError
from ..core.motion import CycleODE
from ..core.tolerances import CYCLE_MATCH
from .simulate import _Setup
from ..model.names import is_angle_name

SAMPLES = 720  # samples of a cycle where the extremes of the speed are first looked for


@dataclass
class Steady:
    """A periodic steady state: the cycle (radians), its time, w0 at the cycle's start,
    the mean, largest and smallest speed (rad per time), the coefficient of fluctuation,
    and the speed at the samples of one cycle (`theta`, `w`)."""

    cycle: float
    period: float
    w0: float
    w_mean: float
    w_max: float
    w_min: float
    theta: np.ndarray
    w: np.ndarray

    @property
    def fluctuation(self) -> float:
        return (self.w_max - self.w_min) / self.w_mean


def cycle_of(setup: _Setup, key: str) -> float:
    """The loads' period in the free angle `key` (radians): the least common multiple of a
    turn and every `KEY % c` in the expressions."""
    obj = key[:-len(".angle")]
    periods = []
    for e in setup.exprs.values():
        if e.uses_time:
            raise ModelError(f"{e.where}: --steady: the loads depend on the time t; a steady "
                             f"state is sought over cycles of {key}")
        periods += [c * setup.angle for x, c in e.periods if x in (f"{obj}.angle", key)]
    turn = 2 * math.pi
    for k in range(1, 25):
        if all(abs(k * turn / c - round(k * turn / c)) < CYCLE_MATCH for c in periods):
            return k * turn
    raise ModelError(f"--steady: no common cycle of one turn and the loads' periods "
                     f"{[math.degrees(c) for c in periods]} deg")


class Shooting:
    """The periodic steady state of one setup (one free angle input, nothing else driven)."""

    def __init__(self, setup: _Setup):
        mo = setup.motion
        if len(mo.free) != 1 or mo.held or not is_angle_name(setup.free[0]):
            raise ModelError("--steady: expected one free angle input and no other input")
        self.setup, self.key = setup, setup.free[0]
        self.cycle = cycle_of(setup, self.key)
        self.ode = CycleODE(mo)

    def run(self, q0, th0, w0, p, tol, n=SAMPLES):
        """(y at the n samples of one cycle from (q0, theta0, w0)), the cycle signed as w0."""
        cyc = math.copysign(self.cycle, w0)
        par = np.concatenate([p, [th0, cyc]])
        y0 = np.concatenate([[0.0], q0, [w0]])
        return self.ode.run(y0, par, n, tol), par, y0

    def steady(self, q0, th0, w0, p, tol) -> Steady:
        """Shoot on w0 until the speed at the end of a cycle is the speed at its start."""
        def miss(w):
            return self.run(q0, th0, w, p, tol, 1)[0][-1, -1] - w
        a, b = w0, self.run(q0, th0, w0, p, tol, 1)[0][-1, -1]  # one cycle: a better start
        fa, fb = miss(a), miss(b)
        for _ in range(60):
            if fb == fa or abs(fb) <= 1e2 * tol * abs(b):
                break
            a, b, fa = b, b - fb * (b - a) / (fb - fa), fb
            if not math.isfinite(b) or b * w0 <= 0:
                raise ModelError("--steady: the machine does not keep turning (no periodic steady state)")
            fb = miss(b)
        else:
            raise ModelError("--steady: the shooting did not converge")
        Y, par, y0 = self.run(q0, th0, b, p, tol)
        Y = np.vstack([y0, Y])
        taus = np.linspace(0, 1, len(Y))
        w = np.abs(Y[:, -1])
        hi = self._extreme(Y, taus, par, tol, int(np.argmax(w)), True)
        lo = self._extreme(Y, taus, par, tol, int(np.argmin(w)), False)
        period = abs(Y[-1, 0])
        return Steady(self.cycle, period, b, self.cycle / period, hi, lo, th0 + par[-1] * taus, Y[:, -1])

    def _extreme(self, Y, taus, par, tol, i, larger: bool):
        """The extreme of the continuous |w(tau)| next to sample i (the largest if `larger`):
        where the cubic Hermite interpolant of (w, dw/dtau) on the neighbouring intervals is
        stationary, w integrated exactly from the sample before it."""
        best = abs(Y[i, -1])
        for a in (i - 1, i):
            if a < 0 or a + 1 >= len(Y):
                continue
            h = taus[a + 1] - taus[a]
            d0, d1 = (self.ode.slope(Y[k], taus[k], par)[-1] * h for k in (a, a + 1))
            w0, w1 = Y[a, -1], Y[a + 1, -1]
            # w(s) = (2s^3 - 3s^2 + 1) w0 + (s^3 - 2s^2 + s) d0 + (-2s^3 + 3s^2) w1 + (s^3 - s^2) d1
            c2, c1 = 3 * (2 * w0 + d0 - 2 * w1 + d1), 2 * (-3 * w0 - 2 * d0 + 3 * w1 - d1)
            roots = np.roots([c2, c1, d0]) if c2 else ([-d0 / c1] if c1 else [])
            for r in roots:
                if abs(np.imag(r)) > 0 or not 0 < np.real(r) < 1:
                    continue
                pp = par.copy()
                pp[-2] = par[-2] + par[-1] * taus[a]  # from sample a, over the fraction h r
                v = abs(self.ode.run(Y[a], pp, 1, tol, upto=h * float(np.real(r)))[-1, -1])
                best = max(best, v) if larger else min(best, v)
        return best

    def net_work(self, q0, th0, w_mean, p, n=SAMPLES):
        """dE of the energy method: the swing of the integral of the net torque at constant
        speed w_mean over a cycle, T(theta) = M theta'' at theta' = w_mean (= -h)."""
        mo, key = self.setup.motion, self.key
        ths = th0 + math.copysign(self.cycle, w_mean) * np.linspace(0, 1, n + 1)
        from .sweeps import sweep
        sw = sweep(self.setup.m, {key: ths}, report=[], guess=None)
        T = np.empty(n + 1)
        for k, th in enumerate(ths):
            u, ud = np.array([th]), np.array([w_mean])
            acc, _ = mo.accelerations(sw.q[k], u, ud, 0.0, p)
            M = float(mo.mass(sw.q[k], u, ud, 0.0, p)[0, 0])
            T[k] = M * acc[0]
        T -= np.trapezoid(T, ths) / (ths[-1] - ths[0])
        E = np.concatenate([[0.0], np.cumsum((T[1:] + T[:-1]) / 2 * np.diff(ths))])
        return float(np.ptp(E))
