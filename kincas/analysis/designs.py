"""Many designs at once: one structure swept for a table of parameter values.

`sweep_designs(m, params, inputs)` solves the mechanism m with each row of `params` (one
design: values of some of its parameters, the others as declared) at every pose of `inputs`,
every design on the branch of m's guess:

1. the nominal design's first pose is assembled from the guess (as `kincas.sweep` does);
2. with a compiler, each design is then solved whole in C (kincas/core/designs_kernel.py):
   its first pose continued from the nominal's in the parameters, along p(t) = p0 + t (p_d -
   p0) (a predictor dq = -g_q^-1 g_p dp, then Newton, in steps of t; a step is kept only
   when its residual is accepted and every Assur group's det g_q kept the nominal's sign:
   the assembly branch), then its poses by the fast pass of `kincas.sweep` (the same kernel
   and checks). Blocks of designs go in one C call each, the blocks on several threads (the
   C loop releases the GIL and shares no buffers);
3. what that loop leaves (rare) is done as before it existed: a pose the fast pass rejects is
   continued carefully (step halving, as `kincas.sweep`'s careful path) and the fast pass goes
   on after it; a first pose it could not continue is continued again with numpy, all such
   designs together, else assembled from the guess and kept if every group has the
   nominal's mode, then swept. Without a compiler, all designs take this path (and advance
   pose by pose together).

Where a design cannot be continued to a pose, `gaps="stop"` (the default) ends it there:
that pose gets "no assembly" (or "branch lost" when Newton finds an assembly there that the
continuation could not reach without leaving the branch) and the later poses "not solved".
`gaps="resume"` instead finishes such a design with `kincas.sweep` from its first pose (which
resumes after gaps, more slowly). Statuses are per design and pose, never an exception.

>>> import numpy as np, kincas
>>> m = kincas.Mechanism(parameters={"a": 1.0, "d": 4.0}, ground={"A": (0, 0), "D": ("d", 0)},
...     links=[kincas.Link.bar("crank", "A", "B", "a"), kincas.Link.bar("coupler", "B", "C", 3.5),
...            kincas.Link.bar("rocker", "D", "C", 3)],
...     inputs=[kincas.Input.angle("crank")], guess={"C": (3.6, 2.9)})
>>> r = kincas.sweep_designs(m, {"a": [0.9, 1.0, 1.1], "d": [4.0, 4.1, 3.9]},
...                          {"crank.angle": np.linspace(0, 2 * np.pi, 73)}, report=["C.y"])
>>> r.values["C.y"].shape, r.design_ok.tolist()
((3, 73), [True, True, True])
"""
from __future__ import annotations

import os
from dataclasses import dataclass
from typing import Mapping

import numpy as np

from ..errors import ModelError
from ..core.numeric import compile as compile_model
from ..model.names import default_report
from ..model.mechanism import Mechanism, as_param
from ..result_base import Result
from .continuation import _first
from .design_job import (BLOCK, BLOCK_POSES, BRANCH_LOST, CALL_SECONDS, FIRST_CALL, FULL_BLOCK,  # noqa: F401
                         NO_ASSEMBLY, NO_MESH, NOT_SOLVED, OK, STATUS, _Job)
from ..core.batch import model_lock as _lock
from .sweeps import _input_table



# --- the result ---


@dataclass(repr=False)
class DesignSweep(Result):
    """Designs x poses. `values[Q]` (n_designs, n_poses) in radians for angles, NaN where a
    pose is not solved; `code` (n_designs, n_poses) indexes STATUS ("ok", "no assembly",
    "not solved", "branch lost"); `params` (n_designs, len(names)) the varied values;
    `inputs` key -> values per pose."""

    names: list[str]
    params: np.ndarray
    inputs: dict[str, np.ndarray]
    values: dict[str, np.ndarray]
    code: np.ndarray

    @property
    def status(self) -> np.ndarray:
        """Status strings per design and pose."""
        return np.array(STATUS, dtype=object)[self.code]

    @property
    def ok(self) -> np.ndarray:
        return self.code == OK

    @property
    def design_ok(self) -> np.ndarray:
        """Whether each design was solved at every pose."""
        return self.ok.all(axis=1)

    def failure(self, d: int) -> tuple[str, int] | None:
        """(status, pose) of design d's first pose that was not solved; None if all were."""
        bad = np.flatnonzero(self.code[d] != OK)
        return None if not len(bad) else (STATUS[self.code[d, bad[0]]], int(bad[0]))

    def summary(self) -> str:
        """Designs solved at every pose, poses, varied parameters, reported quantities."""
        nd, npose = self.code.shape
        return (f"{nd} designs x {npose} poses, {int(self.design_ok.sum())} solved at every pose; "
                f"varied {', '.join(self.names) or 'none'}; reported {', '.join(self.values) or 'none'}")

    def to_pandas(self, length: str = "", angle: str = "rad"):
        """A DataFrame indexed by (design, pose): the varied parameters, the inputs, each
        quantity and `status`; units in `df.attrs["units"]` (`length` names lengths').

        Examples
        --------
        >>> import kincas
        >>> m = kincas.Mechanism(parameters={"a": 2.0}, ground={"O": (0, 0)},
        ...     links=[kincas.Link.bar("crank", "O", "A", "a")], inputs=[kincas.Input.angle("crank")])
        >>> r = kincas.sweep_designs(m, {"a": [1.0, 3.0]}, {"crank.angle": [0.0, 0.5]}, report=["A.x"])
        >>> df = r.to_pandas("mm")
        >>> df.loc[(1, 0), "A.x"], df.attrs["units"]["a"]
        (np.float64(3.0), 'mm')
        """
        from ..frames import designs_to_pandas, in_angle
        return in_angle(designs_to_pandas(self, length), angle)

    def to_xarray(self, length: str = "", angle: str = "rad"):
        """An xarray Dataset with dimensions (design, pose): the varied parameters along
        design, the inputs along pose, each quantity and `status` over both."""
        from ..frames import designs_to_xarray, in_angle
        return in_angle(designs_to_xarray(self, length), angle)


# --- the designs' table ---


def design_table(m: Mechanism, params, names=None) -> tuple[list[str], np.ndarray]:
    """(names, (n_designs, len(names)) values) from a mapping name -> values or a table."""
    if isinstance(params, Mapping):
        names = list(params)
        cols = [np.atleast_1d(np.asarray(params[k], dtype=float)) for k in names]
        if len({len(c) for c in cols}) > 1 or any(c.ndim != 1 for c in cols):
            raise ModelError("params: every parameter needs one value per design")
        X = np.stack(cols, axis=1) if cols else np.zeros((0, 0))
    else:
        X = np.atleast_2d(np.asarray(params, dtype=float))
        names = list(names) if names is not None else [k for k, _ in m.parameters]
        if X.shape[1] != len(names):
            raise ModelError(f"params: {X.shape[1]} columns for {len(names)} names {names}")
    driven = {i.target for i in m.inputs if i.kind == "parameter"}
    problems = [f"params: {k!r}: no such parameter" for k in names if k not in m.param_values]
    problems += [f"params: {k!r}: driven by an input" for k in names if k in driven]
    if not np.isfinite(X).all():
        problems.append("params: expected finite numbers")
    if problems:
        raise ModelError(problems)
    return names, X


def _sizes(m: Mechanism, P: np.ndarray, pnames: list[str]) -> np.ndarray:
    """`Mechanism.size()` of every design (rows of P), vectorised."""
    own = getattr(m, "sizes", None)  # a mechanism that measures its designs itself
    if own is not None:
        return own(P, pnames)
    idx = {k: j for j, k in enumerate(pnames)}

    def val(v):
        p = as_param(v)
        return np.full(len(P), float(v)) if p is None else p.scale * P[:, idx[p.name]]
    ext = np.zeros(len(P))
    for lk in m.links:
        loc = [(val(x), val(y)) for _, (x, y) in lk.points]
        for a in loc:
            for b in loc:
                ext = np.maximum(ext, np.hypot(a[0] - b[0], a[1] - b[1]))
    if m.ground:
        xs = np.stack([val(x) for _, (x, _) in m.ground])
        ys = np.stack([val(y) for _, (_, y) in m.ground])
        ext = np.maximum(ext, np.hypot(xs.max(0) - xs.min(0), ys.max(0) - ys.min(0)))
    return np.where(ext > 0, ext, 1.0)


# --- the sweep ---


def sweep_designs(m: Mechanism, params, inputs=None, *, names=None, rates=None,
                  accelerations=None, report=None, guess=None, workers: int | None = None,
                  gaps: str = "stop", compile: bool | None = None, progress=None,
                  backend: str = "casadi") -> DesignSweep:
    """Sweep the structure of `m` for many parameter sets, each on the branch of the guess.

    Parameters
    ----------
    m : Mechanism
        The nominal design; its guess picks the assembly branch.
    params : mapping or array
        name -> one value per design, or an (n_designs, n_names) table with `names`
        (default: all of m's parameters in order). Parameters not given keep m's values.
    inputs, rates, accelerations, report, guess
        As for `kincas.sweep`.
    workers : int, optional
        Threads for the compiled pass (default: every core).
    gaps : {"stop", "resume"}
        What happens to a design after a pose it cannot reach (see the module's text).
    compile : bool, optional
        As for `kincas.sweep` (None: compile when cached or at least 50,000 poses in all).
    progress : callable, optional
        Called as progress(designs done, designs).
    backend : {"casadi", "jax"}
        The fast pass over the poses: casadi's compiled kernel (default), or JAX
        (`pip install "kincas[gpu]"`; a GPU if JAX has one), its rejected poses continued here
        (kincas/analysis/designs_jax.py).

    Returns
    -------
    DesignSweep
        Values and a status per design and pose (`to_xarray()` for a Dataset).

    Examples
    --------
    Two crank lengths a; at crank angle 0 and pi, B and C lie on the ground line, where
    C.x = +-a + (3.5^2 - 3^2 + r^2) / (2 r), r = 4 -+ a:

    >>> import numpy as np, kincas
    >>> m = kincas.Mechanism(parameters={"a": 1.0}, ground={"A": (0, 0), "D": (4, 0)},
    ...     links=[kincas.Link.bar("crank", "A", "B", "a"), kincas.Link.bar("coupler", "B", "C", 3.5),
    ...            kincas.Link.bar("rocker", "D", "C", 3)],
    ...     inputs=[kincas.Input.angle("crank")], guess={"C": (3.6, 2.9)})
    >>> r = sweep_designs(m, {"a": [0.9, 1.1]}, {"crank.angle": [0.0, np.pi]}, report=["C.x"])
    >>> exact = [[a + (3.25 + (4 - a) ** 2) / (2 * (4 - a)), -a + (3.25 + (4 + a) ** 2) / (2 * (4 + a))]
    ...          for a in (0.9, 1.1)]
    >>> r.design_ok.tolist(), bool(np.abs(r.values["C.x"] - exact).max() < 1e-12)
    ([True, True], True)
    """
    if gaps not in ("stop", "resume"):
        raise ModelError(f"gaps: {gaps!r} is neither \"stop\" nor \"resume\"")
    if backend not in ("casadi", "jax"):
        raise ModelError(f"backend: {backend!r} is neither \"casadi\" nor \"jax\"")
    model = compile_model(m)
    report = list(default_report(m) if report is None else report)
    model.quantity_function(tuple(report))  # unknown names fail here
    names, X = design_table(m, params, names)
    U = _input_table(m, inputs, "inputs", None)
    nd = X.shape[0]
    Ud = np.ascontiguousarray(np.broadcast_to(_input_table(m, rates, "rates", 1.0), U.shape))
    Udd = np.ascontiguousarray(np.broadcast_to(_input_table(m, accelerations, "accelerations", 0.0), U.shape))
    pnames = [k for k, _ in m.parameters]
    p0 = np.array([v for _, v in m.parameters], dtype=float)
    P = np.repeat(p0[None, :], nd, axis=0)
    P[:, [pnames.index(k) for k in names]] = X
    P = np.ascontiguousarray(P)
    Ls = np.ascontiguousarray(_sizes(m, P, pnames))
    g = {k: tuple(map(m.value, xy)) for k, xy in {**dict(m.guess), **dict(guess or {})}.items()}
    job = _Job(model, m, report, U, Ud, Udd, P, Ls, g, compile, progress)
    job.backend = backend
    workers = workers or os.cpu_count() or 1
    with _lock(model):
        nominal = _first(model, U[0], p0, m.size(), g) if nd else None
    job._news(0)
    rest = job.whole_designs(nominal, p0, m.size(), workers)
    with _lock(model):
        job.first_poses(nominal, p0, m.size(), rest)
    job.sweep_all(workers, rest)
    if gaps == "resume":
        job.resume_gaps(names)
    job.fill_values()
    job.check_gears()
    keys = [i.key for i in m.inputs]
    return DesignSweep(names=names, params=X, inputs={k: U[:, j].copy() for j, k in enumerate(keys)},
                       values={nm: job.vals[:, i, :] for i, nm in enumerate(report)}, code=job.code)
