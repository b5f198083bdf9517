"""`sweep_designs(..., backend="jax")`: the designs' fast pass in JAX, the rest as before.

The JAX pass (kincas/core/jax_backend.py) sweeps every design that assembled, from the state
its first pose left, until its first rejected pose; `sweep_designs` then continues each
design from there on the CPU exactly as after a rejection of the compiled pass (careful step
halving, then the compiled pass again), so a pose the JAX pass could not verify is never
taken from it.

Tested against `kincas.sweep` design by design in tests/test_designs_jax.py.
"""
from __future__ import annotations

import numpy as np

from ..core.jax_backend import jax_designs


def jax_pass(job, todo, thresholds) -> np.ndarray:
    """The JAX pass over designs `todo` of a `sweep_designs` job (their first poses solved,
    their kernel states in job.S): fills the accepted poses' unknowns and values, and returns
    each design's first rejected pose (n if none was)."""
    todo = np.asarray(todo, dtype=int)
    jd = jax_designs(job.model, tuple(job.report))
    # poses 1.. of each design written straight into the job's rows (NaN where not accepted)
    stops = jd.run(job.S[todo], job.U, job.P[todo], job.Ls[todo], job.Ud, job.Udd, thresholds,
                   out=(job.Q, job.vals, None), rows=todo)[3]
    k = np.arange(job.U.shape[0])
    acc = (k >= 1) & (k < stops[:, None])  # poses 1..stop-1 accepted; the stop rejected
    job.code[todo] = np.where(acc, 0, job.code[todo])  # 0: "ok"
    job.fast[todo] |= acc
    return stops
