"""Property test: wrong calls on random mechanisms (tests/random_mechanisms.py) raise kincas's
own errors (kincas.KincasError: ModelError, SceneError), never a raw exception, whatever the
mechanism. Each wrong call is drawn from a list of typical mistakes."""
from __future__ import annotations

import numpy as np
import pytest

import kincas
import random_mechanisms as rm

N = rm.count(6)


def mistakes(c):
    """(what, call) pairs: each call must raise kincas.KincasError."""
    m, key = c.mech, c.keys[0]
    U = c.inputs
    good = dict(rates=c.rates)
    return [
        ("an unknown quantity", lambda: kincas.sweep(m, U, report=["nowhere.x"], **good)),
        ("a quantity of an unknown kind", lambda: kincas.sweep(m, U, report=[f"{c.moving[0]}.speed"], **good)),
        ("an unknown input key", lambda: kincas.sweep(m, {"nothing.angle": U[key]}, **good)),
        ("a rate for an unknown input", lambda: kincas.sweep(m, U, rates={"nothing.angle": 1.0})),
        ("an unknown method", lambda: kincas.sweep(m, U, method="quick")),
        ("an effort of no input", lambda: kincas.sweep(m, U, report=["effort(nothing.angle)"])),
        ("a reaction at a point that is no joint", lambda: kincas.sweep(m, U, report=[f"reaction({c.moving[-1]}, nobody).x"])),
        ("a sensitivity to an unknown parameter", lambda: kincas.sweep(m, U, report=[f"d({c.moving[0]}.x)/d(nothing)"])),
        ("an unknown parameter", lambda: m.with_parameters(nothing=1.0)),
        ("a guess of a ground point", lambda: kincas.sweep(m, U, guess={m.ground_points[0]: (0.0, 0.0)})),
        ("a guess of an unknown point", lambda: kincas.sweep(m, U, guess={"nowhere": (0.0, 0.0)})),
        ("a NaN input", lambda: kincas.sweep(m, {k: np.full(3, np.nan) for k in c.keys})),
        ("inputs of different lengths", lambda: kincas.sweep(m, {k: U[k][: 2 + i] for i, k in enumerate(c.keys)}) if len(c.keys) > 1 else kincas.sweep(m, {key: U[key], "x": U[key][:2]})),
        ("an input given as text", lambda: kincas.sweep(m, {k: "fast" for k in c.keys})),
        ("a negative length", lambda: m.with_parameters(**{p: -1.0 for p, _ in m.parameters if p.startswith(("len_", "m_")) and p not in c.keys})),
    ]


def failures_of(family, which):
    failures = []
    for c in rm.cases(family, min(N, 3)):
        for what, call in which(c):
            try:
                call()
            except kincas.KincasError:
                continue
            except Exception as e:  # a raw exception: the user sees a traceback
                failures.append(f"{c.label}: {what}: {type(e).__name__}: {str(e)[:160]}")
            else:
                failures.append(f"{c.label}: {what}: no error")
    return failures


@pytest.mark.parametrize("family", rm.FAMILIES)
def test_wrong_calls_raise_kincas_errors(family):
    failures = failures_of(family, mistakes)
    assert not failures, "\n".join(failures)

