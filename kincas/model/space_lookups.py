"""What a spatial mechanism answers as a planar `Mechanism` does (its parameters, bodies,
joints, points, size, new values): a part of `kincas.SpatialMechanism` (kincas/model/space.py).

>>> from kincas import SpatialMechanism
>>> SpatialMechanism(parameters={"r": 2.0}).parameter("r")
2.0
"""
from __future__ import annotations

import math
from dataclasses import replace

from ..errors import ModelError
from .checks import _number_check
from .lookups import Lookups
from .mobility import GROUND
from typing import TYPE_CHECKING

from .space_parts import Joint, _triple

if TYPE_CHECKING:
    from .space import SpatialMechanism
from .values import _table


class SpatialLookups(Lookups):
    """Lookups and new values of a `SpatialMechanism` (the fields are the dataclass's)."""

    @property
    def links(self) -> tuple:
        """The bodies and bars (named like a planar mechanism's links).

        Examples
        --------
        >>> from kincas import SpatialMechanism, SpatialSlide, Body, Joint, Input
        >>> m = SpatialMechanism(ground={"O": (0, 0, 0)}, bodies=[Body("arm", {"O": (0, 0, 0), "P": (1, 0, 0)})],
        ...     joints=[Joint("revolute", "O", axis=(0, 0, 1))], inputs=[Input.joint("O")])
        >>> [b.name for b in m.links]
        ['arm']
        """
        return self.bodies

    def _fixed_points(self) -> set:
        """The ground's points but a slide joint's: a ground point that is the point of a
        cylindrical, prismatic or planar joint with the ground first moves (it belongs to the
        joint's second body; the ground's copy only marks where the line or plane is drawn).

        Examples
        --------
        >>> from kincas import SpatialMechanism, Body, Joint, Input
        >>> m = SpatialMechanism(ground={"G": (0, 0, 0)}, bodies=[Body("pad", {"G": (0, 0, 0), "P": (1, 0, 0)})],
        ...     joints=[Joint("prismatic", "G", axis=(0, 0, 1))], inputs=[Input.joint("G")])
        >>> m.moving_points
        ('G', 'P')
        """
        return set(dict(self.ground)) - {p for p, b in self.exempt() if b == GROUND}

    def slide_point(self, j) -> tuple:
        """Where a cylindrical, prismatic or planar joint's point is drawn: on its second
        body (the ground's where the ground is second), as written (numbers or parameters).

        Examples
        --------
        >>> from kincas import SpatialMechanism, Body, Joint, Input
        >>> m = SpatialMechanism(ground={"G": (0, 0, 0)}, bodies=[Body("pad", {"G": (0, 0, 0), "P": (1, 0, 0)})],
        ...     joints=[Joint("prismatic", "P", axis=(0, 0, 1))], inputs=[Input.joint("P")])
        >>> m.slide_point(m.joint("P"))
        (1, 0, 0)
        """
        owner = self.joint_bodies(j)[1]
        return dict(self.ground)[j.point] if owner == GROUND else self.link(owner).local(j.point)

    @property
    def redundant(self) -> int:
        """Equations implied by the others (Bennett's, Bricard's linkage): decided by the
        constraint Jacobian's rank at generic assemblies, whatever the guess (as
        `Mechanism.redundant`).

        Examples
        --------
        >>> from kincas import SpatialMechanism, SpatialSlide, Body, Joint, Input
        >>> SpatialMechanism(ground={"O": (0, 0, 0)}, bodies=[Body("arm", {"O": (0, 0, 0), "P": (1, 0, 0)})],
        ...     joints=[Joint("revolute", "O", axis=(0, 0, 1))], inputs=[Input.joint("O")]).redundant
        0
        """
        from .mechanism import Mechanism
        return Mechanism.redundant.fget(self)

    def solved_unknowns(self) -> int:
        """The size of the spatial model's q (kincas/model/space_tree.py: 7 per floating
        body, 4 per body on a ball, a hung body's joint coordinates that no input drives, 3
        per point only bars carry), counted from the declarations.

        Returns
        -------
        int

        Examples
        --------
        >>> from kincas import SpatialMechanism, Body, Joint, Input
        >>> SpatialMechanism(ground={"O": (0, 0, 0)}, bodies=[Body("arm", {"O": (0, 0, 0), "P": (1, 0, 0)})],
        ...     joints=[Joint("revolute", "O", axis=(0, 0, 1))], inputs=[Input.joint("O")]).solved_unknowns()
        0
        """
        from .space_tree import solved_unknowns
        return solved_unknowns(self)

    def joint(self, name: str) -> Joint:
        """The joint of that name.

        Parameters
        ----------
        name : str

        Returns
        -------
        Joint

        Examples
        --------
        >>> from kincas import SpatialMechanism, SpatialSlide, Body, Joint, Input
        >>> m = SpatialMechanism(ground={"O": (0, 0, 0)}, bodies=[Body("arm", {"O": (0, 0, 0), "P": (1, 0, 0)})],
        ...     joints=[Joint("revolute", "O", axis=(0, 0, 1))], inputs=[Input.joint("O")])
        >>> m.joint("O").type
        'revolute'
        """
        return {j.name: j for j in self.joints}[name]

    def _drawn(self):
        """(point, (x, y, z)) as drawn, for every moving point a rigid body carries."""
        out = {}
        for b in self.bodies:
            for p, xyz in b.points:
                if xyz is not None and p not in dict(self.ground):
                    out.setdefault(p, xyz)
        return tuple(out.items())

    def size(self) -> float:
        """The largest distance between two points of a body, a bar's length or the span of
        the ground points (1 if none).

        Returns
        -------
        float

        Examples
        --------
        >>> from kincas import SpatialMechanism, SpatialSlide, Body, Joint, Input
        >>> m = SpatialMechanism(ground={"O": (0, 0, 0)}, bodies=[Body("arm", {"O": (0, 0, 0), "P": (1, 0, 0)})],
        ...     joints=[Joint("revolute", "O", axis=(0, 0, 1))], inputs=[Input.joint("O")])
        >>> m.size()
        1.0
        """
        ext = 0.0
        for b in self.bodies:
            if b.two_point:
                ext = max(ext, abs(self.value(b.length)))
                continue
            pts = [tuple(map(self.value, xyz)) for _, xyz in b.points]
            ext = max([ext] + [math.dist(a, c) for a in pts for c in pts])
        g = [tuple(map(self.value, xyz)) for _, xyz in self.ground]
        ext = max([ext] + [math.dist(a, c) for a in g for c in g])
        return ext if ext > 0 else 1.0

    def sizes(self, P, pnames) -> list[float]:
        """`size()` of each design: row k of P gives the parameters `pnames`.

        Parameters
        ----------
        P : array (designs x parameters)
        pnames : list of str

        Returns
        -------
        numpy.ndarray

        Examples
        --------
        >>> from kincas import SpatialMechanism, SpatialSlide, Body, Joint, Input
        >>> SpatialMechanism(parameters={"r": 2.0}, ground={"O": (0, 0, 0)}, bodies=[Body.bar("b", "O", "P", "r")],
        ...     slides=[SpatialSlide("P", "ground", (0, 0, 0), direction=(1, 0, 0))], guess={"P": (2, 0, 0)}).sizes([[3.0], [4.0]], ["r"]).tolist()
        [3.0, 4.0]
        """
        import numpy as np
        return np.array([self.with_parameters(**dict(zip(pnames, map(float, row)))).size() for row in P])

    def check_guess(self, guess) -> tuple:
        """A guess given to one call, checked as the mechanism's own (ModelError otherwise).

        Parameters
        ----------
        guess : dict
            Point -> (x, y, z).

        Returns
        -------
        tuple

        Examples
        --------
        >>> from kincas import SpatialMechanism, SpatialSlide, Body, Joint, Input
        >>> m = SpatialMechanism(ground={"O": (0, 0, 0)}, bodies=[Body("arm", {"O": (0, 0, 0), "P": (1, 0, 0)})],
        ...     joints=[Joint("revolute", "O", axis=(0, 0, 1))], inputs=[Input.joint("O")])
        >>> m.check_guess({"P": (0, 1, 0)})
        (('P', (0, 1, 0)),)
        """
        items = tuple((k, _triple(v, f"[guess] {k}")) for k, v in _table(guess, "guess", "(x, y, z)"))
        out: list[str] = []
        num = _number_check(self.param_values, out)
        for p, xyz in items:
            if p not in self.moving_points:
                out.append(f"[guess] {p}: is not a moving point")
            for c in xyz:
                num(f"[guess] {p}", c)
        if out:
            raise ModelError(out)
        return items

    def with_guess(self, **points) -> "SpatialMechanism":
        """A new mechanism whose guess is updated (point -> (x, y, z)).

        Parameters
        ----------
        **points : (float, float, float)

        Returns
        -------
        SpatialMechanism

        Examples
        --------
        >>> from kincas import SpatialMechanism, SpatialSlide, Body, Joint, Input
        >>> m = SpatialMechanism(ground={"O": (0, 0, 0)}, bodies=[Body("arm", {"O": (0, 0, 0), "P": (1, 0, 0)})],
        ...     joints=[Joint("revolute", "O", axis=(0, 0, 1))], inputs=[Input.joint("O")])
        >>> dict(m.with_guess(P=(0, 1, 0)).guess)["P"]
        (0, 1, 0)
        """
        return replace(self, guess={**dict(self.guess), **points})

