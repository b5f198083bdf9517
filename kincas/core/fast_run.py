"""The arrays of one fast sweep and the call that solves a stretch of it (`FastRun`).

A `FastRun` binds, once per sweep, one block of memory holding everything the kernel reads or
writes for it (L and the acceptance thresholds, the state of the last solved pose, the
unknowns, the measures of INFO, the reported quantities and the singular measures), and
`advance` hands its addresses to the compiled C loop, else to the virtual machine of its
`FastSweeper` (kincas/core/fast.py, which decides what to do with a rejected pose). `_rows`
and `_take` read rates and accelerations given as a table or as one row for every pose;
`_moved_within` is the test of a first pose the kernel solved from a placed guess
(`FastSweeper._from_guess`), `_ticks` the news of a sweep's progress.

>>> _rows([1.0, 2.0], 5, 2)[1], _rows(np.zeros((5, 2)), 5, 2)[1]
(0, 2)
"""
from __future__ import annotations

import ctypes
from typing import TYPE_CHECKING

import numpy as np

from .compiled import rows, table
from .kernel import CORRECTION, JAC_CHANGE, KERNEL_NEAR, RESIDUAL, STEP

if TYPE_CHECKING:
    from .fast import FastSweeper

INFO = ("residual", "step", "jac_change", "correction", "steps")
# A run's whole sweep in one call (`FastRun.advance` from pose 0 to the end): the addresses of
# the block's parts as byte offsets from its start, one array per layout (`_Layout.at`), so
# that ctypes converts six arguments instead of sixteen (~1.6 us a call). Whenever a call
# reaches the last pose, over every pose's measures (those the call wrote and those written
# before it), what `kincas.sweep` asks of them first (`kincas_measures_summary`):
# how many (pose, group) modes differ from the first pose's (NaN differs from everything),
# and the smallest sigma (NaN if any is), so that Python reads two numbers instead of the
# table (kincas/analysis/events.py `nothing_met_summary`).
WHOLE_C = """
int kincas_measures_summary(casadi_int n, const casadi_real* meas, casadi_real* out) {
  casadi_int i, j, other = 0;
  casadi_real low = INFINITY;
  int nan = 0;
  for (i = 0; i < n; ++i) {
    const casadi_real* m = meas + i*NM;
    for (j = 0; j < NM - 1; ++j) other += !(m[j] == meas[j]);
    if (m[NM - 1] != m[NM - 1]) nan = 1;
    else if (m[NM - 1] < low) low = m[NM - 1];
  }
  out[0] = (casadi_real) other; out[1] = nan ? NAN : low;
  return 0;
}
int kincas_sweep_whole(casadi_int n, char* b, const casadi_int* at, casadi_int max_evals, casadi_int sud,
                       casadi_int sudd) {
  int k = kincas_sweep(n, (const casadi_real*) (b + at[0]), (const casadi_real*) (b + at[1]),
                       (const casadi_real*) b, (const casadi_real*) (b + 8), max_evals, (casadi_real*) (b + at[2]),
                       (casadi_real*) (b + at[3]), (casadi_real*) (b + at[4]), n, (const casadi_real*) (b + at[5]), sud,
                       (const casadi_real*) (b + at[6]), sudd, (casadi_real*) (b + at[7]), (casadi_real*) (b + at[8]));
  kincas_measures_summary(k, (const casadi_real*) (b + at[8]), (casadi_real*) (b + at[9]));
  return k;
}
"""
_I, _V = ctypes.c_longlong, ctypes.c_void_p
WHOLE_SIGS = {"kincas_sweep_whole": [_I, _V, _V, _I, _I, _I], "kincas_measures_summary": [_I, _V, _V]}
_HEAD = np.array([np.nan, RESIDUAL, STEP, JAC_CHANGE, CORRECTION, KERNEL_NEAR])  # L, then thresholds
_F8 = np.dtype(np.float64)
# (numpy's names each run calls, looked up once: `np.name` is a module look-up a call)
_ND, _empty, _zeros = np.ndarray, np.empty, np.zeros
LAYOUTS_KEPT = 64  # layouts remembered per sweeper (sweeps of many lengths: kept bounded)


class _Layout:
    """Where each part of a run's block starts (`FastRun`), for one sweeper and one set of
    sizes (poses, the strides of rates and accelerations, parameters): `off` as `FastRun._off`
    reads it, the shapes of the views, and `at`, the byte offsets of the parts that
    kincas_sweep_whole reads for a call over every pose (start 0, stop N), at `at_address`."""

    __slots__ = ("off", "q_shape", "info_shape", "values_shape", "at", "at_address")

    def __init__(self, off, q_shape, info_shape, values_shape, at):
        self.off, self.q_shape, self.info_shape, self.values_shape = off, q_shape, info_shape, values_shape
        self.at = np.array(at, dtype=np.int64)  # (kept with the layout: the C loop reads it)
        self.at_address = self.at.ctypes.data


def _layout(sweeper, key) -> _Layout:
    """The `_Layout` of `key` = (n, rate stride, acceleration stride, parameters), made once
    per sweeper (a table kept by it; two threads making one at once make the same)."""
    n, sud, sudd, n_p = key
    nq, nu = sweeper.nq, sweeper.nu
    no, nm = len(sweeper.report), len(sweeper.blocks) + 1
    at_ud = 6 + n * nu  # where each part starts: U at 6, then the rates, ...
    at_udd = at_ud + (n if sud else 1) * nu
    at_p = at_udd + (n if sudd else 1) * nu
    at_s = at_p + n_p
    at_q = at_s + sweeper.state_size
    at_info = at_q + n * nq
    at_values = at_info + 5 * n
    at_m = at_values + no * n
    # (the order `advance` and the views read them in: state, Q, info, values, measures,
    # U, rates, accelerations, parameters, then the ends of the parameters and measures, then
    # the end of the measures' summary, two numbers: the block's size)
    o = (0, at_s, at_q, at_info, at_values, at_m, 6, at_ud, at_udd, at_p, at_s, at_m + nm * n, at_m + nm * n + 2)
    # the C loop's addresses at start 0, in bytes from the block's: U, p, state, Q, info,
    # rates, accelerations, values, measures, then the measures' summary
    lay = _Layout(o, (n, nq), (5, n), (no, n), [8 * o[i] for i in (6, 9, 1, 2, 3, 7, 8, 4, 5, 11)])
    kept = sweeper._layouts
    if len(kept) >= LAYOUTS_KEPT:
        kept.clear()
    kept[key] = lay
    return lay


class FastRun:
    """The arrays of one sweep, bound once; `advance` solves a stretch of it per call.

    `Q` (N, nq): the unknowns, NaN where not solved; `values` (len(report), N): the reported
    quantities; `info` (5, N): per pose attempted, the measures named in INFO; `measures`
    (groups + 1, N): per pose, the sign of det of each Assur group's block of g_q, then the
    smallest lower bound of a group's smallest singular value (relative, columns scaled,
    kincas/core/blocks.py); `accepted`: the poses the fast pass accepted; `solved`: by either
    path (`FastSweeper.sweep` fills it); `first_bad`: where the last `advance` stopped. The
    arrays are not initialised (filling 100,000 rows with NaN costs more than solving them):
    rows that no `advance` or `record` reached are NaN only after `run` or `sweep` returns.
    Everything the kernel writes belongs to this run: runs in several threads share nothing.
    """

    # (slots: a sweep makes one run, and each attribute stored in a __dict__ of twenty costs
    # it more; `__dict__` stays for what callers add, such as `crossed`)
    __slots__ = ("sweeper", "n", "_off", "_block", "Q", "info", "values", "_ok", "solved", "_accepted",
                 "_measures", "_state_view", "_sud", "_sudd", "_U", "_Ud", "_Udd", "_p", "first_bad", "_s", "_lay",
                 "_addr", "recorded", "attempted", "backend", "summarised", "__dict__")

    crossed = ()  # steps across a gap the careful path found (kincas/analysis/continuation.py
    # sets a list of its own where it finds one; read by `kincas.sweep` without a getattr
    # that fails, whose exception costs a microsecond)

    def __init__(self, sweeper: "FastSweeper", U, p, L, Ud=None, Udd=None):
        self.sweeper, nu = sweeper, sweeper.nu
        if not (type(U) is _ND and U.ndim == 2 and U.shape[1] == nu and U.dtype == _F8):
            U = table(U, nu)
        self.n = n = U.shape[0]
        Ud, sud = _rows(np.ones(nu) if Ud is None else Ud, n, nu)
        Udd, sudd = _rows(np.zeros(nu) if Udd is None else Udd, n, nu)
        if not (type(p) is _ND and p.dtype == _F8 and p.ndim == 1):  # (a mechanism's
            p = np.asarray(p, dtype=float).ravel()  # prepared values are: no call for them)
        # everything the kernel reads or writes of this run in one block of memory: L and
        # the thresholds, copies of the inputs (U, rates, accelerations: a table, or one row
        # for every pose) and the parameters, then the state, Q, info, values, measures (one
        # address per run: numpy's array interface costs ~1.5 us an array). The views a warm
        # sweep does not read (the measures, the state, the inputs) are made when first asked.
        # Where each part starts depends on the sizes alone: worked out once per sweeper and
        # sizes (`_Layout`).
        key = (n, sud, sudd, p.size)
        lay = sweeper._layouts.get(key)
        if lay is None:
            lay = _layout(sweeper, key)
        o = self._off = lay.off
        block = self._block = _empty(o[12])
        # (a slice assigned each: a quarter less than one np.concatenate of the five)
        block[:6] = _HEAD  # the thresholds, then L in its place
        block[0] = L
        block[6:o[7]] = U.ravel()
        block[o[7]:o[8]] = Ud.ravel()
        block[o[8]:o[9]] = Udd.ravel()
        block[o[9]:o[10]] = p
        self.Q = block[o[2]:o[3]].reshape(lay.q_shape)
        self.info = block[o[3]:o[4]].reshape(lay.info_shape)
        self.values = block[o[4]:o[5]].reshape(lay.values_shape)
        self._lay, self._sud, self._sudd = lay, sud, sudd
        self._U = self._Ud = self._Udd = self._p = self._measures = self._state_view = self._accepted = None
        self._ok = ok = _zeros((2, n), dtype=bool)  # accepted, solved: one table, set by one call
        self.solved = ok[1]
        self.first_bad, self._s, self._addr, self.recorded = 0, None, None, 0
        self.attempted = False  # True once every pose was attempted (`FastSweeper.sweep`)
        self.backend = None  # "compiled" or "virtual machine": what `advance` ran last
        self.summarised = False  # the block's summary is of every pose (`summary`)

    @property
    def accepted(self) -> np.ndarray:
        """(N,) bool: the poses the fast pass accepted."""
        a = self._accepted
        if a is None:
            a = self._accepted = self._ok[0]
        return a

    @property
    def measures(self) -> np.ndarray:
        """(groups + 1, N): per pose, the sign of det of each Assur group's block of g_q,
        then the smallest relative singular value bound (the kernel writes one pose's
        together: a row per measure of 100,000 poses would be 41 streams of writes on 40
        chained four-bars, 1.7 us a pose)."""
        m = self._measures
        if m is None:
            m = self._measures = self.measures_by_pose()[0].T
        return m

    @property
    def _state(self) -> np.ndarray:
        """The kernel's state (`FastSweeper.state`) in the run's block."""
        s = self._state_view
        if s is None:
            s = self._state_view = self._block[self._off[1]:self._off[2]]
        return s

    @property
    def U(self) -> np.ndarray:
        """(N, nu) the inputs at each pose (the run's copy, which the kernel reads)."""
        if self._U is None:
            self._U = self._block[self._off[6]:self._off[7]].reshape(self.n, self.sweeper.nu)
        return self._U

    @property
    def Ud(self) -> tuple:
        """(table, row stride): the inputs' rates, one row per pose (stride nu) or one for all (0)."""
        if self._Ud is None:
            self._Ud = (_rows_of(self._block[self._off[7]:self._off[8]], self._sud, self.sweeper.nu), self._sud)
        return self._Ud

    @property
    def Udd(self) -> tuple:
        """(table, row stride): the inputs' accelerations, as `Ud`."""
        if self._Udd is None:
            self._Udd = (_rows_of(self._block[self._off[8]:self._off[9]], self._sudd, self.sweeper.nu), self._sudd)
        return self._Udd

    @property
    def p(self) -> np.ndarray:
        """The parameter values (the run's copy)."""
        if self._p is None:
            self._p = self._block[self._off[9]:self._off[10]]
        return self._p

    L = property(lambda self: self._block[0:1], doc="(1,) the length the residuals are relative to")
    thr = property(lambda self: self._block[1:6], doc="(5,) the kernel's acceptance thresholds")
    residual = property(lambda self: self.info[0], doc="max |g| / L at each pose (L: each group's)")
    step = property(lambda self: self.info[1], doc="the last Newton step (negligible, applied)")
    jac_change = property(lambda self: self.info[2], doc="max per group of sum |D^-1 (A_prev^-1 A - I) D|")
    correction = property(lambda self: self.info[3], doc="max per group of ||D^-1 (q - q_pred)||_1")
    iterations = property(lambda self: self.info[4].astype(int) if self.attempted else _counts(self.info[4]),
                          doc="Newton steps taken at each pose (0 where none was attempted)")
    signs = property(lambda self: self.measures[:-1].T, doc="(N, groups) signs of det per group")
    sigma = property(lambda self: self.measures[-1], doc="smallest relative singular value bound")

    def measures_by_pose(self) -> tuple:
        """The measures as the kernel writes them: (N, groups + 1), and the same in one row."""
        flat = self._block[self._off[5]:self._off[11]]
        return flat.reshape(self.n, len(self.sweeper.blocks) + 1), flat

    def summary(self) -> tuple | None:
        """(modes that differ from the first pose's, the smallest sigma, NaN if any is) over
        every pose's measures, as the compiled loop summed them when its last call reached
        the last pose; None otherwise (the measures are then read from the table)."""
        if not self.summarised:
            return None
        at = self._off[11]
        return self._block[at], self._block[at + 1]

    def modes_at(self, k: int) -> list:
        """Each group's mode at pose k (the sign of det of its block of g_q), as numbers."""
        nm = len(self.sweeper.blocks) + 1
        at = self._off[5] + k * nm
        return self._block[at:at + nm - 1].tolist()

    def advance(self, start: int, q_last, u_last, stop: int | None = None) -> int:
        """Solve poses start, start + 1, ... (before `stop`, default N) from the solved pose
        (q_last, u_last) until one is rejected, and return its index (`stop` if none was).
        The poses before it are accepted; the rejected pose keeps its `info` (why) and NaN in
        `Q` and `values`. q_last None: go on from where the last call stopped, unrejected."""
        sw, stop = self.sweeper, self.n if stop is None else min(stop, self.n)
        if start >= stop or not (sw.nq and sw.nu):  # nothing to predict: all careful
            return min(start, stop)
        if q_last is not None or self._s is None:
            self._s = sw.state(q_last, u_last, self.p, out=self._state)
        s = self._s  # the C loop leaves the last accepted pose's state in it
        lib = sw.backend.lib  # (loaded: `Backend.compiled` would answer it)
        if lib is None:
            lib = sw.backend.compiled(self.n)
        self.backend = "virtual machine" if lib is None else "compiled"
        if lib is not None:
            a = self._addr
            if a is None:  # the address of the run's block (inputs included): a ctypes view
                # of the (writable, contiguous) block costs a third of `ptr`'s
                a = self._addr = ctypes.addressof(ctypes.c_char.from_buffer(self._block))
            if start == 0 and stop == self.n:  # (the usual warm sweep: its addresses as byte
                # offsets worked out once per layout, `_Layout.at`; the measures summarised)
                k = lib.kincas_sweep_whole(stop, a, self._lay.at_address, sw.max_evals, self._sud, self._sudd)
                self.summarised = k == stop > 0
            else:
                o, sud, sudd, nq, nu = self._off, self._sud, self._sudd, sw.nq, sw.nu
                k = start + lib.kincas_sweep(
                    stop - start, a + 8 * (o[6] + start * nu), a + 8 * o[9], a, a + 8, sw.max_evals, a + 8 * o[1],
                    a + 8 * (o[2] + start * nq), a + 8 * (o[3] + start), self.n, a + 8 * (o[7] + start * sud), sud,
                    a + 8 * (o[8] + start * sudd), sudd, a + 8 * (o[4] + start),
                    a + 8 * (o[5] + start * (len(sw.blocks) + 1)))
                self.summarised = k == self.n > 0  # the last stretch: every pose's measures summarised
                if self.summarised:  # (those before `start` as `record` or an earlier call wrote them)
                    lib.kincas_measures_summary(self.n, a + 8 * o[5], a + 8 * o[11])
        else:
            self.summarised = False
            k = sw._vm_advance(self, start, stop, s)
        if start == 0 and k == self.n:  # (the usual warm sweep: every pose at once)
            self._ok.fill(True)  # accepted and solved
        else:
            self._ok[:, start:k] = True
        if k < stop:
            self.Q[k] = self.values[:, k] = self.measures[:, k] = np.nan
        self.first_bad = k
        return k

    def record(self, k: int, sol) -> None:
        """Store a carefully solved pose (an object with q, residual, iterations, ok, J)."""
        self.recorded += 1
        self.summarised = False
        self.solved[k] = bool(sol.ok)
        self.Q[k], self.values[:, k] = (sol.q if sol.ok else np.nan), np.nan  # values: see sweep
        self.measures[:, k] = self.sweeper.measures(sol, self.U[k], self.p, self.L[0]) if sol.ok else np.nan
        self.info[:, k] = [sol.residual, np.nan, np.nan, np.nan, sol.iterations]

def _rows(a, n: int, width: int) -> tuple[np.ndarray, int]:
    """`rows` (kincas/core/compiled.py) with its usual cases first: a C-contiguous (n, width)
    table as it is, one row (or a table broadcast from one) as that row with stride 0."""
    if not (type(a) is _ND and a.dtype == _F8):  # (np.asarray's keywords cost more)
        a = np.asarray(a, dtype=float)
    if a.ndim == 2 and a.shape == (n, width) and width:
        if a.strides[0] == 0:
            return np.ascontiguousarray(a[0]), 0
        if a.flags.c_contiguous:
            return a, width
    if a.size == width and width:
        return np.ascontiguousarray(a.reshape(width)), 0
    return rows(a, n, width)


def _counts(steps: np.ndarray) -> np.ndarray:
    """Newton's steps per pose as integers, NaN (a pose not attempted) as 0 (np.fmax calls
    libm per number: a run whose every pose was attempted skips it)."""
    return np.fmax(steps, 0.0).astype(int)


def _rows_of(a: np.ndarray, stride: int, width: int) -> np.ndarray:
    """A table's rows in the run's block: (N, width) with stride `width`, one row with 0."""
    return a.reshape(-1, width) if stride else a


def _take(table, idx):
    a, stride = table
    return a if stride == 0 else a[idx]


# --- a sweep's first pose from a placed guess, and news of progress (`FastSweeper.sweep`) ---


def _ticks(progress, n: int):
    """tick(a, b): news at every 256th pose passed from a to b, as the careful path gives it
    (`FastSweeper.sweep`); the first news, progress(0, n), given now."""
    def tick(a, b):
        if b // 256 > a // 256:
            progress(b - b % 256, n)
    progress(0, n)
    return tick


def _moved_within(q, q0, w, groups: list, group_of: np.ndarray, n_groups: int) -> bool:
    """Whether each group's sum of |q - q0| w over its own unknowns (in the order of q) is
    at most CORRECTION (`FastSweeper._from_guess`): q0 and w as lists (a few unknowns, summed
    in Python; `groups` None where every unknown is in the one group) or as arrays (np.bincount adds each group's terms in the same order, so the
    sums are the same numbers; where one is NaN, Python's max decides as it always did)."""
    if type(q0) is list:
        if groups is None:  # every unknown in the one group: its sum alone, in the same order
            moved = 0.0
            for a, b, x in zip(q.tolist(), q0, w):
                moved += abs(a - b) * x
            return moved <= CORRECTION  # (NaN: not, as max([nan]) is nan)
        moved = [0.0] * (n_groups + 1)  # (the last: unknowns of no group)
        for g, a, b, x in zip(groups, q.tolist(), q0, w):
            moved[g] += abs(a - b) * x
        return max(moved[:-1], default=0.0) <= CORRECTION
    d = np.abs(q - q0)
    d *= w
    moved = np.bincount(group_of, d, n_groups + 1)
    top = moved[:-1].max() if n_groups else 0.0
    if top == top:  # (no NaN: the largest, as Python's max finds it)
        return bool(top <= CORRECTION)
    return _moved_within(q, q0.tolist(), w.tolist(), groups, group_of, n_groups)
