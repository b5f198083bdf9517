"""The fast pass of many designs in JAX: one scan over the poses per design, vmapped over designs.

An optional backend (`pip install "kincas[gpu]"`: jax and jaxadi) for `kincas.sweep_designs(...,
backend="jax")`. The arithmetic is the fast kernel's (kincas/core/kernel.py), not a rewrite:
its casadi SX Functions kP (the prediction along the tangent), kN (a Newton step, group by
group) and kF (g_q, the tangent, the acceptance measures and the reported quantities) are
translated instruction by instruction into JAX functions by `jaxadi`, and driven as the C
loop drives them: kP, kN until its step is below KERNEL_NEAR (at most MAX_EVALS times, a
`lax.while_loop`), kF. For each design a `lax.scan` carries the kernel's state (q, g_q's
diagonal blocks, the tangents and inputs of the last two poses) over the poses, and `vmap`
runs the designs side by side; `jit` compiles it once per structure and shape (kept by the
model, `Model.memo`). Everything runs in float64 (`jax.enable_x64`, set around each call, so other
JAX users in the process keep their own setting).

A pose is accepted by the kernel's own tests: residual max|g| / L and the next Newton step
below their thresholds, the Jacobian-change bound per Assur group below JAC_CHANGE (which
keeps each group's det g_q sign between consecutive poses), the correction from the
prediction small, and besides, the sign of each group's determinant equal to the design's
first pose's. A design's first rejected pose ends its pass (`stops`): the caller continues
it carefully on the CPU (kincas/analysis/designs.py), as the compiled pass's rejections are.

The translation (`to_jax`) goes through `jaxadi.convert` with jaxadi's table of casadi
operations, written as straight-line code (XLA compiles it about ten times sooner than
jaxadi's work-array layout) with every constant exact (jaxadi writes 16 decimals, which
keeps 8 digits of 1.2345678e-9).

>>> import casadi as ca, numpy as np
>>> x = ca.SX.sym("x", 2)
>>> f = ca.Function("f", [x], [ca.vertcat(ca.sin(x[0]) * x[1], ca.if_else(x[0] < x[1], 1e-9, 2.0))])
>>> with x64():
...     y = to_jax(f)(np.array([0.5, 3.0]))[0]
>>> np.array_equal(np.asarray(y), f([0.5, 3.0]).full().ravel()), y.dtype
(True, dtype('float64'))
"""
from __future__ import annotations

import os
import threading
from concurrent.futures import ThreadPoolExecutor

import casadi as ca
import numpy as np

from ..errors import ModelError
from .fast import sweeper_for
from .tolerances import TRANSLATION_ATOL, TRANSLATION_RTOL

CPU_CHUNK = 1024  # designs per jitted call on a CPU (one chunk per core at a time)
GPU_BYTES = 1 << 28  # results per jitted call on a GPU, about (designs x poses x (nq + report))
MIN_CHUNK = 64  # designs are padded to a power of two from here: few shapes, few compiles


# --- jax, imported when asked for ---


def _jax():
    """(jax, jaxadi), or a one-line error naming the extra that provides them."""
    try:
        import jax
        import jaxadi
    except ImportError as e:  # an optional backend: say how to get it
        raise ModelError(f"backend \"jax\": {e.name} is not installed (pip install \"kincas[gpu]\")") from None
    return jax, jaxadi


def available() -> bool:
    """Whether jax and jaxadi can be imported."""
    try:
        _jax()
    except ModelError:
        return False
    return True


def x64():
    """A context in which JAX computes in float64 (thread-local, undone on exit)."""
    jax, _ = _jax()
    if hasattr(jax, "enable_x64"):
        return jax.enable_x64(True)
    from jax.experimental import enable_x64  # before jax 0.6
    return enable_x64()


# --- casadi -> JAX ---


def _literal(c: float) -> str:
    """A constant as Python source that reads back as exactly the same double."""
    if np.isnan(c):
        return "jnp.nan"
    if np.isinf(c):
        return "jnp.inf" if c > 0 else "-jnp.inf"
    return repr(float(c))


_LOGIC = (ca.OP_LT, ca.OP_LE, ca.OP_EQ, ca.OP_NE, ca.OP_NOT, ca.OP_AND, ca.OP_OR)


def _translate(f: ca.Function) -> str:
    """Python source of a JAX function computing f: one line per casadi instruction, each
    operation written as jaxadi writes it (its table of casadi operations), in straight-line
    code: XLA compiles that about ten times sooner than jaxadi's own layout (a work array
    updated layer by layer) and runs it faster. Comparisons give 0.0 or 1.0 as in casadi (a
    bool would add as `or`); constants are written exactly."""
    from jaxadi._ops import OP_JAX_EXPAND_VALUE_DICT as ops

    lines = [f"def evaluate_{f.name()}(*args):",
             "    a = [jnp.ravel(jnp.asarray(x).T) for x in args]"]
    outs: dict = {}
    for i in range(f.n_instructions()):
        op, o, ii = f.instruction_id(i), f.instruction_output(i), f.instruction_input(i)
        if op == ca.OP_CONST:
            rhs = _literal(f.instruction_constant(i))
        elif op == ca.OP_INPUT:
            rhs = f"a[{ii[0]}][{ii[1]}]"
        elif op == ca.OP_OUTPUT:  # taken now: the work variable is reused later
            outs.setdefault(o[0], {})[o[1]] = name = f"o{o[0]}_{o[1]}"
            lines.append(f"    {name} = w{ii[0]}")
            continue
        elif op in ops:
            rhs = ops[op].format(*(f"w{j}" for j in ii))
            rhs = f"jnp.where({rhs}, 1.0, 0.0)" if op in _LOGIC else rhs
        else:
            raise ModelError(f"backend \"jax\": casadi operation {op} has no JAX translation")
        lines.append(f"    w{o[0]} = {rhs}")
    res = []
    for k in range(f.n_out()):
        got = outs.get(k, {})
        res.append("jnp.stack([" + ", ".join(f"jnp.asarray({got.get(j, '0.0')}, dtype=jnp.float64)"
                                            for j in range(f.numel_out(k))) + "])")
    lines.append(f"    return [{', '.join(res)}]")
    return "\n".join(lines)


def to_jax(f: ca.Function):
    """A JAX function computing the casadi SX Function f (through `jaxadi.convert`): arguments
    are arrays of f's input shapes, results are flat vectors (matrices column-major). Call
    (and jit) it under `x64()`, or it computes in float32."""
    _, jaxadi = _jax()
    return jaxadi.convert(f, translate=_checked)


def _checked(f: ca.Function) -> str:
    """`_translate(f)`, tested against f at random arguments first, the source run by numpy
    (instantly, no compilation): a wrong translation would also miscompute the acceptance
    tests that guard the values, so it is refused here."""
    src = _translate(f)
    scope: dict = {"jnp": np}
    exec(src, scope)
    rng = np.random.default_rng(0)
    args = [rng.uniform(0.5, 1.5, f.size_in(i)) for i in range(f.n_in())]
    with np.errstate(all="ignore"):
        got = scope[f"evaluate_{f.name()}"](*args)
    want = f.call(args)
    for k, (a, b) in enumerate(zip(got, want)):
        a, b = np.asarray(a, dtype=float), np.asarray(b).ravel(order="F")
        if a.shape != b.shape or not np.allclose(a, b, rtol=TRANSLATION_RTOL, atol=TRANSLATION_ATOL, equal_nan=True):
            raise ModelError(f"backend \"jax\": the translation of {f.name()} differs from casadi "
                             f"in output {k}")
    return src


# --- the scan over poses, vmapped over designs ---


class JaxDesigns:
    """The fast pass of one compiled model and report over many designs, in JAX.

    `run(S, U, P, Ls, Ud, Udd, thr)` sweeps each design d from its kernel state S[d] (at pose
    0, laid out as `FastSweeper.state`) over the poses 1.. of U and returns (Q (nd, n, nq),
    values (nd, len(report), n), info (nd, 5, n), stops (nd,)): poses 1..stops[d]-1 of design
    d accepted, the rest NaN (`info`: the measures of INFO in kincas/core/fast.py). With
    `out=(Q, values, info)` and `rows`, design d's poses 1.. are written into rows[d] of those
    arrays instead (info None: not kept). Safe from several threads (jitted functions are).
    """

    def __init__(self, model, report=()):
        _jax()
        self.sweeper = sw = sweeper_for(model, tuple(report), False)
        self.nq, self.nu, self.no = sw.nq, sw.nu, len(sw.report)
        self.blocks, self.nj = sw.blocks, sw.nj
        self._fn = None
        self._lock = threading.Lock()

    def _compiled(self):
        with self._lock:
            if self._fn is None:
                self._fn = self._build()
            return self._fn

    def _build(self):
        jax, _ = _jax()
        jnp, lax = jax.numpy, jax.lax
        # a kernel written group by group (kincas/core/group_kernel.py) calls SX functions
        # from MX ones: inlined into one SX function each for the translation
        kP, kN, kF, kL = (to_jax(f.expand() if f.is_a("MXFunction") else f) for f in self.sweeper.functions[:4])
        max_evals = self.sweeper.max_evals
        cuts = np.cumsum(self.sweeper.state_parts[:-2]).tolist()  # (the two flags: one part)

        def design(s0, p, L, signs0, U, Ud, Udd, thr):
            (Lb,) = kL(U[0], p)  # each group's length, at the first pose as the C loop has it

            def pose(carry, x):
                s, alive = carry
                u, ud, udd = x

                def newton(c):  # Newton until the step just applied makes the next negligible
                    q, it, _ = c
                    dq, rs = kN(q, u, p, Lb)
                    return q - dq, it + 1, rs[1] <= thr[4]
                # (the poses before the last two, and the C loop's flags: unused, the cubic
                # predicts every pose here)
                q0, J0, T0, u0, T1, u1, q1, T2, u2, q2, flags = jnp.split(s, cuts)
                (qp,) = kP(q0, T0, u0, u, T1, u1, q1)
                q, it, _ = lax.while_loop(lambda c: ~c[2] & (c[1] < max_evals), newton,
                                          (qp, jnp.int64(0), jnp.bool_(False)))
                J, T, rf, mc, meas, y, dq = kF(q, u, p, L, ud, udd, J0, qp, Lb)
                conv = (rf[0] <= thr[0]) & (rf[1] <= thr[1])  # the next step negligible: applied
                q = jnp.where(conv, q - dq, q)
                ok = (alive & conv & (mc[0] <= thr[2]) & (mc[1] <= thr[3])
                      & jnp.all(meas[:-1] == signs0))
                s1 = jnp.concatenate([q, J, T, u, T0, u0, q0, T1, u1, q1, flags])
                keep = lambda a: jnp.where(ok, a, jnp.nan)
                info = jnp.concatenate([rf, mc, it[None].astype(jnp.float64)])
                return (jnp.where(ok, s1, s), ok), (keep(q), keep(y), keep(info), ok)
            _, out = lax.scan(pose, (s0, jnp.bool_(True)), (U, Ud, Udd))
            return out

        return jax.jit(jax.vmap(design, in_axes=(0, 0, 0, 0, None, None, None, None)))

    def signs(self, S) -> np.ndarray:
        """(nd, groups): the sign of det of each group's block of g_q at the states S."""
        out, at = [], self.nq
        for b in self.blocks:
            k = len(b.cols)
            A = S[:, at:at + k * k].reshape(-1, k, k).transpose(0, 2, 1)  # column-major blocks
            out.append(np.sign(np.linalg.det(A)))
            at += k * k
        return np.stack(out, axis=1) if out else np.zeros((len(S), 0))

    def run(self, S, U, P, Ls, Ud, Udd, thr, *, out=None, rows=None, workers: int | None = None):
        nd, n = S.shape[0], U.shape[0]
        if out is None:
            out, rows = (np.full((nd, n, self.nq), np.nan), np.full((nd, self.no, n), np.nan),
                         np.full((nd, 5, n), np.nan)), np.arange(nd)
        Q, vals, info = out
        stops = np.ones(nd, dtype=int)
        if nd == 0 or n < 2:
            return Q, vals, info, stops
        fn, sg = self._compiled(), self.signs(S)
        jax, _ = _jax()
        jnp = jax.numpy
        cpu = jax.default_backend() == "cpu"
        # On a CPU, chunks of CPU_CHUNK designs on every core (XLA runs one chunk on one
        # core); on a GPU, chunks of about GPU_BYTES of results, one after the other.
        per_design = 8 * n * (self.nq + self.no + 6)
        chunk = CPU_CHUNK if cpu else max(MIN_CHUNK, GPU_BYTES // per_design)
        workers = (workers or os.cpu_count() or 1) if cpu else 1

        def part(a):
            b = min(nd, a + chunk)
            size = max(MIN_CHUNK, 1 << (b - a - 1).bit_length())  # padded: few shapes
            pad = lambda x: np.concatenate([x[a:b], np.repeat(x[a:a + 1], size - (b - a), 0)])
            with x64():  # per thread: the setting is thread-local
                xs = [jnp.asarray(x[1:], dtype=jnp.float64) for x in (U, Ud, Udd)]
                q, y, inf, ok = fn(*(jnp.asarray(pad(x), dtype=jnp.float64)
                                     for x in (S, P, Ls.reshape(-1, 1), sg)), *xs,
                                   jnp.asarray(thr, dtype=jnp.float64))
                w, r = b - a, rows[a:b]
                Q[r, 1:] = np.asarray(q)[:w]
                vals[r, :, 1:] = np.asarray(y)[:w].transpose(0, 2, 1)
                if info is not None:
                    info[r, :, 1:] = np.asarray(inf)[:w].transpose(0, 2, 1)
                stops[a:b] = 1 + np.asarray(ok)[:w].sum(axis=1)
        starts = range(0, nd, chunk)
        if workers > 1 and len(starts) > 1:
            with ThreadPoolExecutor(workers) as ex:  # each writes its own rows
                list(ex.map(part, starts))
        else:
            for a in starts:
                part(a)
        return Q, vals, info, stops


def jax_designs(model, report=()) -> JaxDesigns:
    """The `JaxDesigns` of a compiled model and report (built once, kept by the model)."""
    return model.memo(("jax designs", tuple(report)), lambda: JaxDesigns(model, report))
