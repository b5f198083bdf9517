"""`sweep_designs(..., backend="jax")`: the designs' fast pass in JAX, the rest as before.

The JAX pass (kincas/core/jax_backend.py) sweeps every design that assembled, from the state
its first pose left, until its first rejected pose; `sweep_designs` then continues each
design from there on the CPU exactly as after a rejection of the compiled pass (careful step
halving, then the compiled pass again), so a pose the JAX pass could not verify is never
taken from it.

>>> import numpy as np, kincas
>>> m = kincas.Mechanism(parameters={"a": 1.0}, ground={"A": (0, 0), "D": (4, 0)},
...     links=[kincas.Link.bar("crank", "A", "B", "a"), kincas.Link.bar("coupler", "B", "C", 3.5),
...            kincas.Link.bar("rocker", "D", "C", 3)],
...     inputs=[kincas.Input.angle("crank")], guess={"C": (3.6, 2.9)})
>>> r = kincas.sweep_designs(m, {"a": [0.9, 1.1]}, {"crank.angle": np.linspace(0, 6.2, 63)},
...                          report=["C.y"], backend="jax")  # doctest: +SKIP
>>> r.design_ok.tolist()  # doctest: +SKIP
[True, True]
"""
from __future__ import annotations

import numpy as np

from ..core.jax_backend import jax_designs

BACKENDS = ("casadi", "jax")


def jax_pass(job, todo, thresholds) -> np.ndarray:
    """The JAX pass over designs `todo` of a `sweep_designs` job (their first poses solved,
    their kernel states in job.S): fills the accepted poses' unknowns, values and measures,
    and returns each design's first rejected pose (n if none was)."""
    todo = np.asarray(todo, dtype=int)
    jd = jax_designs(job.model, tuple(job.report))
    Q, vals, info, stops = jd.run(job.S[todo], job.U, job.P[todo], job.Ls[todo], job.Ud, job.Udd,
                                  thresholds)
    for j, d in enumerate(todo):
        k = stops[j]  # poses 1..k-1 accepted; k rejected (if < n)
        job.Q[d, 1:k], job.vals[d, :, 1:k] = Q[j, 1:k], vals[j, :, 1:k]
        job.code[d, 1:k], job.fast[d, 1:k] = 0, True  # 0: "ok"
    return stops
