"""Results of a solve or a sweep, indexed by the scene format's quantity names.

Values are numpy arrays in SI-free user units (lengths as declared, angles in radians); a
pose that was not solved has NaN values and a status other than "ok". Link angles are
wrapped to (-pi, pi].

>>> import numpy as np
>>> s = Sweep(inputs={"crank.angle": np.array([0.0, 1.0])}, rates={}, accelerations={},
...           status=["ok", "no assembly"], flags=[None, None],
...           values={"C.x": np.array([1.5, np.nan])}, q=np.zeros((2, 1)),
...           residual=np.zeros(2), iterations=np.zeros(2, int), unknowns=["q"], size=1.0)
>>> float(s["C.x"][0]), s.ok.tolist(), s.pose(1).status
(1.5, [True, False], 'no assembly')
>>> (s.status == "ok").tolist(), "C.x" in s, list(s)
([True, False], True, ['crank.angle', 'C.x'])
>>> s
<Sweep: 2 poses, 1 solved, 1 not solved; inputs crank.angle; reported C.x>
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .result_base import Result, listed as _names
from .result_later import _Later, install, trues, wrap_angle, wrap_angles  # noqa: F401 (wrap_angle: its old home)


@dataclass(repr=False)
class Pose(Result):
    """One solved (or unsolved) pose: `pose["C.x"]` is a float (NaN when not solved).

    A pose is a container of names, as a `Sweep` is (inputs, then reported quantities).

    Parameters
    ----------
    inputs : dict
        The inputs' values (radians for angles).
    status : str
        "ok", or why the pose was not solved ("no assembly", ...).
    flag : str or None
        "limit", "change point" or "singular" at or near a singular position.
    values : dict
        The reported quantities.
    residual : float
        The loop-closure residual, relative to each group's size.

    Examples
    --------
        >>> import kincas
    >>> m = kincas.Mechanism(ground={"O": (0, 0)}, links=[kincas.Link.bar("crank", "O", "A", 2)],
    ...                      inputs=[kincas.Input.angle("crank")])
    >>> pose = kincas.solve(m, {"crank.angle": 0.0}, report=["A.x"])
    >>> pose.status, pose["A.x"], list(pose)
    ('ok', 2.0, ['crank.angle', 'A.x'])
    """

    inputs: dict[str, float]
    status: str
    flag: str | None
    values: dict[str, float]
    residual: float

    @property
    def ok(self) -> bool:
        """Whether the pose was solved (status "ok").

        Examples
        --------
        >>> Pose({"crank.angle": 0.0}, "no assembly", None, {"C.x": float("nan")}, float("inf")).ok
        False
        """
        return self.status == "ok"

    def __getitem__(self, name: str) -> float:
        return self.values[name] if name in self.values else self.inputs[name]

    def __contains__(self, name) -> bool:
        return name in self.values or name in self.inputs

    def __iter__(self):  # inputs, then reported quantities; a name once (an input may be reported)
        return iter(dict.fromkeys([*self.inputs, *self.values]))

    def __repr__(self) -> str:
        at = ", ".join(f"{k}={v:.6g}" for k, v in self.inputs.items())
        flag = f" ({self.flag})" if self.flag else ""
        return f"<Pose {at}: {self.status}{flag}; {len(self.values)} values>"

    def summary(self) -> str:
        """The status, and how many values (the `repr`'s body).

        Examples
        --------
        >>> Pose({}, "no assembly", None, {"C.x": float("nan")}, float("inf")).summary()
        'no assembly; 1 values'
        """
        return f"{self.status}{f' ({self.flag})' if self.flag else ''}; {len(self.values)} values"

    def to_pandas(self, length: str = "", angle: str = "rad"):
        """A one-row DataFrame, as `Sweep.to_pandas` gives for a sweep.

        Parameters
        ----------
        length, angle : str
            As for `Sweep.to_pandas`.

        Examples
        --------
        >>> Pose({"crank.angle": 0.0}, "ok", None, {"C.x": 1.5}, 0.0).to_pandas("mm").attrs["units"]["C.x"]
        'mm'
        """
        from .frames import in_angle, pose_to_pandas
        return in_angle(pose_to_pandas(self, length), angle)

    def to_xarray(self, length: str = "", angle: str = "rad"):
        """A Dataset along `pose` (of length 1), as `Sweep.to_xarray` gives.

        Parameters
        ----------
        length, angle : str
            As for `Sweep.to_xarray`.

        Examples
        --------
        >>> float(Pose({"crank.angle": 0.0}, "ok", None, {"C.x": 1.5}, 0.0).to_xarray()["C.x"][0])
        1.5
        """
        from .frames import in_angle, pose_to_xarray
        return in_angle(pose_to_xarray(self, length), angle)


@dataclass(repr=False)
class Sweep(Result):
    """Poses over a sweep of the inputs: `sweep["C.x"]` is an array with one entry per pose.

    A sweep is a container of names (the inputs', then the reported quantities'): `"C.x" in
    sweep`, `list(sweep)`, `for name in sweep`. `status` is a numpy array of strings, one per
    pose ("ok", or why the pose was not solved, such as "no assembly"), so `sweep.status ==
    "ok"` is a boolean mask, the same as `sweep.ok`; `flags` names poses at or near a singular
    position ("limit", "change point", "singular", else None). Values are radians for angles,
    whatever the scene's unit (`Scene.user_values` converts). `to_pandas()` and `to_xarray()`
    give the same data as a DataFrame or a Dataset (extra `kincas[data]`).

    Parameters
    ----------
    inputs, rates, accelerations : dict
        Per input, its values (and first and second time derivatives) at every pose.
    status : sequence of str
        Per pose, "ok" or why it was not solved.
    flags : list
        Per pose, "limit", "change point", "singular" or None.
    values : dict
        Per reported quantity, its values.
    q, residual, iterations : numpy.ndarray
        Per pose, the unknowns, the relative residual, Newton's iterations.
    unknowns : list of str
        The unknowns' names.
    size : float
        The mechanism's size.
    events, info : list, dict
        Singular positions met and resumptions; details of how the sweep was solved.

    Examples
    --------
        >>> import kincas
    >>> m = kincas.Mechanism(ground={"O": (0, 0)}, links=[kincas.Link.bar("crank", "O", "A", 2)],
    ...                      inputs=[kincas.Input.angle("crank")])
    >>> sw = kincas.sweep(m, {"crank.angle": [0.0, 1.5707963267948966]}, report=["A.x", "A.y"])
    >>> np.round(sw["A.y"], 12).tolist(), sw.ok.tolist(), list(sw)
    ([0.0, 2.0], [True, True], ['crank.angle', 'A.x', 'A.y'])
    """

    inputs: dict[str, np.ndarray]
    rates: dict[str, np.ndarray]
    accelerations: dict[str, np.ndarray]
    status: np.ndarray  # strings, one per pose (a list given is made an array)
    flags: list[str | None]
    values: dict[str, np.ndarray]
    q: np.ndarray  # the unknowns at each pose (NaN when not solved)
    residual: np.ndarray  # loop-closure residual relative to the size, per pose
    iterations: np.ndarray
    unknowns: list[str]
    size: float
    events: list[dict] = field(default_factory=list)  # singular positions met, resumptions
    info: dict = field(default_factory=dict)

    def __post_init__(self):
        # (the status is made an object array by its setter, `_set_status`)
        wrap_angles(self.values)

    def __len__(self) -> int:
        return len(self.status)

    def __getitem__(self, name: str) -> np.ndarray:
        if name in self.values:
            return self.values[name]
        if name in self.inputs:
            return self.inputs[name]
        raise KeyError(f"{name!r} was not reported (reported: {list(self.values)})")

    def __contains__(self, name) -> bool:
        return name in self.values or name in self.inputs

    def __iter__(self):  # inputs, then reported quantities; a name once (an input may be reported)
        return iter(dict.fromkeys([*self.inputs, *self.values]))

    def keys(self) -> list[str]:
        """The names: inputs, then reported quantities (so `dict(sweep)` works).

        Returns
        -------
        list of str

        Examples
        --------
        >>> import kincas
        >>> m = kincas.Mechanism(ground={"O": (0, 0)}, links=[kincas.Link.bar("crank", "O", "A", 2)],
        ...                      inputs=[kincas.Input.angle("crank")])
        >>> sw = kincas.sweep(m, {"crank.angle": [0.0, 1.5707963267948966]}, report=["A.x", "A.y"])
        >>> sw.keys(), sorted(dict(sw))
        (['crank.angle', 'A.x', 'A.y'], ['A.x', 'A.y', 'crank.angle'])
        """
        return list(self)

    def __repr__(self) -> str:
        return f"<Sweep: {self.summary()}>"

    def __str__(self) -> str:
        return "\n".join(self.summary_lines())

    def summary(self) -> str:
        """Poses solved and not, the inputs and the reported quantities (the `repr`'s body).

        Examples
        --------
        >>> z = np.zeros(2); Sweep({"t": z}, {}, {}, ["ok", "no"], [None] * 2, {"C.x": z}, z, z, z, [], 1).summary()
        '2 poses, 1 solved, 1 not solved; inputs t; reported C.x'
        """
        return f"{self._counts()}; inputs {_names(self.inputs)}; reported {_names(self.values)}"

    def _counts(self) -> str:
        n, good = len(self), int(self.ok.sum())
        return f"{n} pose{'s' if n != 1 else ''}, {good} solved" + (f", {n - good} not solved" if good < n else "")

    def summary_lines(self) -> list[str]:
        """A few lines: poses, solved, flags, events, the inputs' ranges, the quantities.

        Returns
        -------
        list of str

        Examples
        --------
        >>> import kincas
        >>> m = kincas.Mechanism(ground={"O": (0, 0)}, links=[kincas.Link.bar("crank", "O", "A", 2)],
        ...                      inputs=[kincas.Input.angle("crank")])
        >>> sw = kincas.sweep(m, {"crank.angle": [0.0, 1.5707963267948966]}, report=["A.x", "A.y"])
        >>> for line in sw.summary_lines():
        ...     print(line)
        Sweep: 2 poses, 2 solved
          input crank.angle: 0 to 1.5708
          reported: A.x, A.y
        """
        out = [f"Sweep: {self._counts()}"]
        bad = {str(s): int(c) for s, c in zip(*np.unique(self.status[~self.ok].astype(str), return_counts=True))}
        if bad:
            out.append("  not solved: " + ", ".join(f"{c} {s}" for s, c in bad.items()))
        flags = [f for f in self.flags if f]
        if flags:
            kinds = dict.fromkeys(flags)
            out.append("  flagged: " + ", ".join(f"{flags.count(k)} {k}" for k in kinds))
        if self.events:
            kinds = [e.get("kind", "event") for e in self.events]
            out.append("  events: " + ", ".join(f"{kinds.count(k)} {k}" for k in dict.fromkeys(kinds)))
        for k, v in self.inputs.items():
            v = np.asarray(v, float)
            out.append(f"  input {k}: {v.min():.6g} to {v.max():.6g}" if v.size else f"  input {k}")
        out.append(f"  reported: {_names(self.values, 8) or 'nothing'}")
        return out

    # --- in the data tools (extra kincas[data]) ---
    def to_pandas(self, length: str = "", angle: str = "rad"):
        """A DataFrame: one row per pose, the inputs as index, a column per quantity, then
        `status` and `flag`; units (radians, and `length` if named) in `df.attrs["units"]`.
        A reported quantity that is also an input (the driven link's angle) is the index, as
        the input was given (not wrapped), so `df.reset_index()` gives one column of each name.

        Parameters
        ----------
        length : str
            The unit of lengths, recorded in the units ("" : none).
        angle : {"rad", "deg"}
            Angles, angular rates and derivatives of angles in radians (as held) or degrees.

        Examples
        --------
        >>> import kincas
        >>> m = kincas.Mechanism(ground={"O": (0, 0)}, links=[kincas.Link.bar("crank", "O", "A", 2)],
        ...                      inputs=[kincas.Input.angle("crank")])
        >>> sw = kincas.sweep(m, {"crank.angle": [0.0, 1.5707963267948966]}, report=["A.x", "A.y"])
        >>> df = sw.to_pandas("m")
        >>> list(df.columns), df.attrs["units"]["A.x"]
        (['A.x', 'A.y', 'status', 'flag'], 'm')
        """
        from .frames import sweep_to_pandas, in_angle
        return in_angle(sweep_to_pandas(self, length), angle)

    def to_xarray(self, length: str = "", angle: str = "rad"):
        """A Dataset along the dimension `pose`: inputs as coordinates, each quantity a variable
        with `attrs["units"]`, and `status`, `flag`, `ok`, `residual`.

        Parameters
        ----------
        length, angle : str
            As for `to_pandas`.

        Examples
        --------
        >>> import kincas
        >>> m = kincas.Mechanism(ground={"O": (0, 0)}, links=[kincas.Link.bar("crank", "O", "A", 2)],
        ...                      inputs=[kincas.Input.angle("crank")])
        >>> ds = kincas.sweep(m, {"crank.angle": [0.0, 1.5707963267948966]}, report=["A.x"]).to_xarray("m")
        >>> ds["A.x"].attrs["units"], ds.sizes["pose"]
        ('m', 2)
        """
        from .frames import sweep_to_xarray, in_angle
        return in_angle(sweep_to_xarray(self, length), angle)

    @property
    def ok(self) -> np.ndarray:
        """Boolean mask of the solved poses (the same as `status == "ok"`).

        Examples
        --------
        >>> import kincas
        >>> m = kincas.Mechanism(ground={"O": (0, 0)}, links=[kincas.Link.bar("crank", "O", "A", 2)],
        ...                      inputs=[kincas.Input.angle("crank")])
        >>> sw = kincas.sweep(m, {"crank.angle": [0.0, 1.5707963267948966]}, report=["A.x", "A.y"])
        >>> sw.ok.tolist(), (sw.status == "ok").tolist()
        ([True, True], [True, True])
        """
        st = self.__dict__["_status"]
        if type(st) is _Later:  # never read (nor set): every pose "ok"
            return trues(st.args[0])
        st, n = self.status, len(self.status)  # every pose solved (the usual sweep): list.count
        if type(st) is np.ndarray and st.dtype == object and st.ndim == 1 and st.tolist().count("ok") == n:
            return trues(n)  # compares by identity first (numpy's == calls __eq__: 3x)
        return np.asarray(st == "ok", dtype=bool).reshape(n)

    @property
    def names(self) -> list[str]:
        """The reported quantities' names (without the inputs).

        Examples
        --------
        >>> import kincas
        >>> m = kincas.Mechanism(ground={"O": (0, 0)}, links=[kincas.Link.bar("crank", "O", "A", 2)],
        ...                      inputs=[kincas.Input.angle("crank")])
        >>> sw = kincas.sweep(m, {"crank.angle": [0.0, 1.5707963267948966]}, report=["A.x", "A.y"])
        >>> sw.names
        ['A.x', 'A.y']
        """
        return list(self.values)

    def pose(self, i: int) -> Pose:
        """Pose i of the sweep.

        Parameters
        ----------
        i : int

        Returns
        -------
        Pose

        Examples
        --------
        >>> import kincas
        >>> m = kincas.Mechanism(ground={"O": (0, 0)}, links=[kincas.Link.bar("crank", "O", "A", 2)],
        ...                      inputs=[kincas.Input.angle("crank")])
        >>> sw = kincas.sweep(m, {"crank.angle": [0.0, 1.5707963267948966]}, report=["A.x", "A.y"])
        >>> p = sw.pose(1)
        >>> p.status, round(p["A.y"], 12)
        ('ok', 2.0)
        """
        return Pose(inputs={k: float(v[i]) for k, v in self.inputs.items()},
                    status=str(self.status[i]), flag=self.flags[i],
                    values={k: float(v[i]) for k, v in self.values.items()},
                    residual=float(self.residual[i]))


install(Sweep)  # status, flags and iterations: made when first read (kincas/result_later.py)
