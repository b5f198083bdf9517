"""How a sweep solves its poses, as pluggable objects: `kincas.sweep(m, inputs, method=...)`.

The problem (mechanism, inputs, report) is declared apart from the method that solves it, as
rockit's `Ocp.solve()` hands itself to `self._method.solve(self)`: `kincas.sweep` prepares the
problem once (model, input tables, the careful path from the last solved pose) and calls the
method's `sweep(problem)`, which returns the solved run. Two methods ship:

- `Fast(compile=None)` (the default): a compiled pass over the poses, checked pose by pose,
  each pose it does not accept re-solved on the careful path;
- `Careful()`: the careful path (Newton continued from the last solved pose, cutting the
  step where it fails) at every pose.

The strings of 0.1 still work, unchanged and without warning: `method="fast", compile=c` is
`Fast(compile=c)` and `method="careful"` is `Careful()` (`method_of`), so there is one code
path. A method of one's own subclasses `SweepMethod` and composes the problem's two passes,
`problem.fast_pass(compile)` (None where there is no fast pass worth running) and
`problem.careful_pass()`.

>>> import numpy as np, kincas
>>> m = kincas.Mechanism(ground={"A": (0, 0), "D": (4, 0)},
...     links=[kincas.Link.bar("crank", "A", "B", 1), kincas.Link.bar("coupler", "B", "C", 3.5),
...            kincas.Link.bar("rocker", "D", "C", 3)],
...     inputs=[kincas.Input.angle("crank")], guess={"C": (3.6, 2.9)})
>>> th = np.linspace(0, 2 * np.pi, 9)
>>> a = kincas.sweep(m, {"crank.angle": th}, report=["C.x"], method=kincas.Careful())
>>> b = kincas.sweep(m, {"crank.angle": th}, report=["C.x"], method="careful")
>>> bool((a["C.x"] == b["C.x"]).all())
True
"""
from __future__ import annotations

from abc import ABC, abstractmethod

from ..errors import ModelError


class SweepMethod(ABC):
    """How `kincas.sweep` solves the poses of a prepared problem: subclass it and give
    `sweep(problem)`.

    `problem` offers two passes, each returning the run the sweep reads its poses from:
    `problem.fast_pass(compile)` (None where the mechanism has no fast pass, or one that
    would not pay for itself on this sweep) and `problem.careful_pass()`. Its attributes
    `n` (the number of poses) and `report` (the quantity names) help a method choose.

    Examples
    --------
    A method that counts its calls, then solves as `Careful` does:

    >>> import numpy as np, kincas
    >>> class Counted(kincas.SweepMethod):
    ...     calls = 0
    ...     def sweep(self, problem):
    ...         Counted.calls += 1
    ...         return problem.careful_pass()
    >>> m = kincas.Mechanism(ground={"A": (0, 0), "D": (4, 0)},
    ...     links=[kincas.Link.bar("crank", "A", "B", 1), kincas.Link.bar("coupler", "B", "C", 3.5),
    ...            kincas.Link.bar("rocker", "D", "C", 3)],
    ...     inputs=[kincas.Input.angle("crank")], guess={"C": (3.6, 2.9)})
    >>> sw = kincas.sweep(m, {"crank.angle": np.linspace(0, 1, 5)}, method=Counted())
    >>> Counted.calls, bool(sw.ok.all())
    (1, True)
    """

    @abstractmethod
    def sweep(self, problem):
        """Solve the poses of `problem` and return its run.

        Parameters
        ----------
        problem : kincas.analysis.sweeps.SweepProblem
            The sweep, prepared: `fast_pass(compile)`, `careful_pass()`, `n`, `report`.

        Examples
        --------
        >>> import kincas
        >>> kincas.Careful().sweep.__doc__ is not None
        True
        """


class _Shipped(SweepMethod):
    """The methods kincas ships: values, equal where their settings (their __slots__) are,
    printed as they are written."""

    __slots__ = ()

    def _settings(self) -> tuple:
        return tuple((k, getattr(self, k)) for k in type(self).__slots__)

    def __eq__(self, other):
        return type(other) is type(self) and other._settings() == self._settings()

    def __hash__(self):
        return hash((type(self), self._settings()))

    def __repr__(self):
        return f"kincas.{type(self).__name__}({', '.join(f'{k}={v!r}' for k, v in self._settings())})"


class Fast(_Shipped):
    """The default method: a compiled pass over the poses, checked pose by pose; every pose
    it does not accept is re-solved on the careful path, and the pass restarts after it.

    Parameters
    ----------
    compile : bool, optional
        None (the default) compiles the pass to C when a compiled library is cached or the
        sweep is long, compiles it in a background thread when a structure is swept again
        (500 poses in all) or its sweeps add up to 20,000 poses, and leaves the fast pass out where it would not pay (a large
        mechanism, a short sweep); True compiles it (unless the kernel is too large for the
        compiler to be worth waiting for); False runs it in CasADi's virtual machine.
        Whichever runs, `Sweep.info["fast pass"]` says.

    Examples
    --------
    >>> import numpy as np, kincas
    >>> m = kincas.Mechanism(ground={"A": (0, 0), "D": (4, 0)},
    ...     links=[kincas.Link.bar("crank", "A", "B", 1), kincas.Link.bar("coupler", "B", "C", 3.5),
    ...            kincas.Link.bar("rocker", "D", "C", 3)],
    ...     inputs=[kincas.Input.angle("crank")], guess={"C": (3.6, 2.9)})
    >>> sw = kincas.sweep(m, {"crank.angle": np.linspace(0, 1, 50)}, method=kincas.Fast(compile=False))
    >>> sw.info["fast pass"], kincas.Fast(compile=False)
    ('virtual machine', kincas.Fast(compile=False))
    """

    __slots__ = ("compile",)

    def __init__(self, compile: bool | None = None):
        self.compile = compile

    def sweep(self, problem):
        """The fast pass where there is one worth running, else the careful path.

        Parameters
        ----------
        problem : kincas.analysis.sweeps.SweepProblem

        Examples
        --------
        >>> import kincas
        >>> kincas.Fast().compile is None
        True
        """
        run = problem.fast_pass(self.compile)
        return run if run is not None else problem.careful_pass()


class Careful(_Shipped):
    """The careful path at every pose: Newton from the last solved pose (predicted along the
    exact tangent), cutting the step where it fails; slower than `Fast`, for checking it.

    Examples
    --------
    >>> import numpy as np, kincas
    >>> m = kincas.Mechanism(ground={"A": (0, 0), "D": (4, 0)},
    ...     links=[kincas.Link.bar("crank", "A", "B", 1), kincas.Link.bar("coupler", "B", "C", 3.5),
    ...            kincas.Link.bar("rocker", "D", "C", 3)],
    ...     inputs=[kincas.Input.angle("crank")], guess={"C": (3.6, 2.9)})
    >>> sw = kincas.sweep(m, {"crank.angle": np.linspace(0, 1, 5)}, method=kincas.Careful())
    >>> sw.info["fast pass"] is None, bool(sw.ok.all())
    (True, True)
    """

    __slots__ = ()

    def sweep(self, problem):
        """Every pose on the careful path.

        Parameters
        ----------
        problem : kincas.analysis.sweeps.SweepProblem

        Examples
        --------
        >>> import kincas
        >>> kincas.Careful() == kincas.Careful()
        True
        """
        return problem.careful_pass()


# the strings' methods, made once: a warm sweep pays one dictionary look-up for them
_CAREFUL = Careful()
_FAST = {None: Fast(None), True: Fast(True), False: Fast(False)}


def method_of(method, compile) -> SweepMethod:
    """The method `sweep(method=..., compile=...)` asks for: an instance as given, "fast"
    as `Fast(compile)`, "careful" as `Careful()` (which ignores `compile`, as 0.1 did).
    ModelError naming `method` for anything else, and naming `compile` beside an instance
    (which carries its own, as `Fast(compile=...)`)."""
    if isinstance(method, str):  # (first: the default; an ABC's isinstance costs ~1 us)
        if method == "fast":
            return _FAST[compile] if compile is None or type(compile) is bool else Fast(compile)
        if method == "careful":
            return _CAREFUL
    elif isinstance(method, SweepMethod):
        if compile is not None:
            raise ModelError(f"compile: {method!r} is a method object; give compile to it, "
                             f"as kincas.Fast(compile={compile!r})")
        return method
    raise ModelError(f"method: {method!r:.80} is neither \"fast\", \"careful\" nor a "
                     f"kincas.SweepMethod (kincas.Fast(), kincas.Careful())")
