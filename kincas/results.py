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
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


def wrap_angle(a: np.ndarray) -> np.ndarray:
    """Wrap radians to (-pi, pi]."""
    w = np.mod(np.asarray(a, dtype=float) + np.pi, 2 * np.pi) - np.pi
    return np.where(w == -np.pi, np.pi, w)


@dataclass
class Pose:
    """One solved (or unsolved) pose: `pose["C.x"]` is a float (NaN when not solved)."""

    inputs: dict[str, float]
    status: str
    flag: str | None
    values: dict[str, float]
    residual: float

    @property
    def ok(self) -> bool:
        return self.status == "ok"

    def __getitem__(self, name: str) -> float:
        return self.values[name] if name in self.values else self.inputs[name]


@dataclass
class Sweep:
    """Poses over a sweep of the inputs: `sweep["C.x"]` is an array with one entry per pose."""

    inputs: dict[str, np.ndarray]
    rates: dict[str, np.ndarray]
    accelerations: dict[str, np.ndarray]
    status: list[str]
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
        for k in list(self.values):
            if k.endswith((".angle", ".phi")) and not k.startswith("d("):  # cam.phi too
                self.values[k] = wrap_angle(self.values[k])

    def __len__(self) -> int:
        return len(self.status)

    def __getitem__(self, name: str) -> np.ndarray:
        if name in self.values:
            return self.values[name]
        if name in self.inputs:
            return self.inputs[name]
        raise KeyError(f"{name!r} was not reported (reported: {list(self.values)})")

    @property
    def ok(self) -> np.ndarray:
        """Boolean mask of the solved poses."""
        return np.array([s == "ok" for s in self.status], dtype=bool)

    @property
    def names(self) -> list[str]:
        return list(self.values)

    def pose(self, i: int) -> Pose:
        return Pose(inputs={k: float(v[i]) for k, v in self.inputs.items()},
                    status=self.status[i], flag=self.flags[i],
                    values={k: float(v[i]) for k, v in self.values.items()},
                    residual=float(self.residual[i]))
