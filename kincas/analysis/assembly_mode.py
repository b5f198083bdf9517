"""One assembly mode: the `Mode` record, and how it is built from the unknowns q of a
solved pose (shared by the multistart search, kincas/analysis/modes.py, and the certified
one, kincas/analysis/certify.py).

>>> Mode(np.zeros(1), ("a",), {"C": (1.0, -2.5)}, {}, 0.0, 1).guess
{'C': (1.0, -2.5)}
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..core.tolerances import BRANCH, SAME_ASSEMBLY as SAME
from ..errors import ModelError
from ..model.mechanism import Mechanism
from ..results import wrap_angle
from .inputs import input_table


@dataclass(frozen=True)
class Mode:
    """One real assembly: the unknowns `q`, the moving points' positions, the link angles
    (radians, wrapped to (-pi, pi]), the relative residual after polishing, the sign of the
    Jacobian's determinant (which side of the singular positions the mode lies on; 0 when
    singular), and whether the mechanism's own guess leads to it."""

    q: np.ndarray
    unknowns: tuple[str, ...]
    points: dict[str, tuple[float, float]]
    angles: dict[str, float]
    residual: float
    orientation: int
    from_guess: bool = False
    inputs: dict[str, float] = field(default_factory=dict)

    @property
    def guess(self) -> dict[str, tuple[float, float]]:
        """The points as a guess: `kincas.sweep(m, ..., guess=mode.guess)` follows this mode."""
        return dict(self.points)

    def guess_block(self, digits: int = 12) -> str:
        """A `[guess]` section for a scene file that picks this mode.

        >>> Mode(np.zeros(1), ("a",), {"C": (1.0, -2.5)}, {}, 0.0, 1).guess_block()
        '[guess]\\nC = [1, -2.5]\\n'
        """
        rows = [f"{p} = [{', '.join(f'{c:.{digits}g}' for c in xy)}]" for p, xy in self.points.items()]
        return "[guess]\n" + "".join(r + "\n" for r in rows)


def input_vector(m: Mechanism, inputs) -> np.ndarray:
    """One finite value per input (the pose at which the modes are wanted)."""
    U = input_table(m, {} if inputs is None and not m.inputs else inputs, "inputs", None)
    if U.shape[0] != 1:
        raise ModelError("inputs: expected one value per input (modes are found at one pose)")
    return U[0]


def signature(model, Q, u, p, L) -> np.ndarray:
    """One row per row of unknowns Q that tells assemblies apart: the moving points
    (x1, y1[, z1], x2, ...) and, for a spatial body, its rotation matrix times the size L.
    Points alone fix every planar link's angle, but not a spatial body's spin about the line
    of its points (a shaft held at two points: the double Cardan's intermediate shaft has
    the same points in two assemblies turned half a turn apart about it).

    >>> import kincas
    >>> from kincas.core.numeric import model_of
    >>> m = kincas.Mechanism(ground={"A": (0, 0)}, links=[kincas.Link.bar("crank", "A", "B", 2)],
    ...     inputs=[kincas.Input.angle("crank")])
    >>> signature(model_of(m), np.zeros((1, 0)), np.array([0.0]), np.zeros(0), 2.0).round(9).tolist()
    [[2.0, 0.0]]
    """
    Q = np.atleast_2d(np.asarray(Q, float))
    rows = [model.points_many(Q, u, p)]
    rotations = getattr(model, "rotations_many", None)  # a model of rigid bodies in space
    if rotations is not None and len(Q):
        rows.append(L * rotations(Q, u, p))
    return np.hstack(rows)


def mode_at(m, model, q, u, p, L, picked=None, pts=None, kind=None, **extra) -> Mode:
    """The `Mode` at unknowns q: its points, link angles, relative residual, orientation, and
    whether it is the assembly `picked` (a `signature` row, or None); `kind` a subclass of
    Mode built with the `extra` fields (kincas/analysis/certify.py)."""
    names = m.moving_points
    pts = model.points(q, u, p).T.ravel() if pts is None else pts
    # each mode's angles: the links' (or, where the model names them, its own: joint angles)
    angles = getattr(model, "mode_angles", lambda: [(lk.name, f"{lk.name}.angle") for lk in m.links])()
    links, dim = [a for a, _ in angles], getattr(model, "dim", 2)
    s = model.column_scale(L)  # columns scaled to O(1)
    ang = model.quantities([qn for _, qn in angles], q[None, :], u[None, :], p,
                           np.ones((1, len(u))), np.zeros((1, len(u))))[:, 0]
    J = model.jac(q, u, p) * s if model.nq else np.eye(1)
    det = np.linalg.det(J) if J.shape[0] == J.shape[1] else 0.0  # tall (redundant): no sign
    res = float(np.abs(model.residual(q, u, p)).max(initial=0.0) / L)
    return (kind or Mode)(
        q=np.array(q), unknowns=tuple(model.unknown_names),
        points={nm: tuple(float(c) for c in pts[dim * j:dim * j + dim]) for j, nm in enumerate(names)},
        angles={lk: float(wrap_angle(a)) for lk, a in zip(links, ang)},
        residual=res, orientation=int(np.sign(det)) if abs(det) > BRANCH else 0,
        from_guess=bool(picked is not None and
                        np.abs(signature(model, q, u, p, L)[0] - picked).max() <= SAME * L),
        inputs={i.key: float(v) for i, v in zip(m.inputs, u)}, **extra)
