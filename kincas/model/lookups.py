"""What every mechanism answers, planar (`kincas.Mechanism`) and spatial
(`kincas.SpatialMechanism`), from its fields: parameters and their values, links (or bodies)
and slides by name, ground and moving points, the counted mobility, and a new mechanism with
some parameters changed. One implementation: the two kinds differ only in their fields'
coordinates (2 or 3), which these lookups never read.

>>> from kincas import Input, Link, Mechanism
>>> Mechanism(parameters={"r": 2.0}, ground={"O": (0, 0)},
...     links=[Link.bar("crank", "O", "A", "r")], inputs=[Input.angle("crank")]).parameter("r")
2.0
"""
from __future__ import annotations

from dataclasses import replace

from ..errors import ModelError
from .parts import Num, as_param, is_number


class Lookups:
    """Lookups and new values shared by `Mechanism` and `SpatialMechanism` (which give the
    fields `parameters`, `ground`, `links` (a spatial one's bodies), `slides`, `structure`)."""

    @property
    def param_values(self) -> dict[str, float]:
        """The parameters as a dict: name -> value.

        Examples
        --------
        >>> from kincas import Input, Link, Mechanism, Param, Slide
        >>> m = Mechanism(parameters={"r": 2.0}, ground={"O": (0, 0)},
        ...     links=[Link.bar("crank", "O", "A", "r")], inputs=[Input.angle("crank")])
        >>> m.param_values
        {'r': 2.0}
        """
        return dict(self.parameters)

    def parameter(self, name: str) -> float:
        """A parameter's value.

        Parameters
        ----------
        name : str

        Returns
        -------
        float

        Examples
        --------
        >>> from kincas import Input, Link, Mechanism, Param, Slide
        >>> m = Mechanism(parameters={"r": 2.0}, ground={"O": (0, 0)},
        ...     links=[Link.bar("crank", "O", "A", "r")], inputs=[Input.angle("crank")])
        >>> m.parameter("r")
        2.0
        """
        return self.param_values[name]

    def link(self, name: str):
        """The link of that name.

        Parameters
        ----------
        name : str

        Returns
        -------
        Link

        Examples
        --------
        >>> from kincas import Input, Link, Mechanism, Param, Slide
        >>> m = Mechanism(parameters={"r": 2.0}, ground={"O": (0, 0)},
        ...     links=[Link.bar("crank", "O", "A", "r")], inputs=[Input.angle("crank")])
        >>> m.link("crank").point_names
        ('O', 'A')
        """
        return {lk.name: lk for lk in self.links}[name]

    def slide(self, name: str):
        """The slide of that name.

        Parameters
        ----------
        name : str

        Returns
        -------
        Slide

        Examples
        --------
        >>> from kincas import Input, Link, Mechanism, Param, Slide
        >>> m = Mechanism(ground={"O": (0, 0)},
        ...     links=[Link.bar("crank", "O", "A", 1), Link.bar("rod", "A", "B", 3)],
        ...     slides=[Slide("B", "ground", name="guide")], inputs=[Input.angle("crank")])
        >>> m.slide("guide").point
        'B'
        """
        return {s.name: s for s in self.slides}[name]

    @property
    def ground_points(self) -> tuple[str, ...]:
        """The ground points' names, in declaration order.

        Examples
        --------
        >>> from kincas import Input, Link, Mechanism, Param, Slide
        >>> m = Mechanism(parameters={"r": 2.0}, ground={"O": (0, 0)},
        ...     links=[Link.bar("crank", "O", "A", "r")], inputs=[Input.angle("crank")])
        >>> m.ground_points
        ('O',)
        """
        return tuple(g for g, _ in self.ground)

    @property
    def moving_points(self) -> tuple[str, ...]:
        """Points carried by links and not fixed to the ground, in declaration order.

        Examples
        --------
        >>> from kincas import Input, Link, Mechanism, Param, Slide
        >>> m = Mechanism(parameters={"r": 2.0}, ground={"O": (0, 0)},
        ...     links=[Link.bar("crank", "O", "A", "r")], inputs=[Input.angle("crank")])
        >>> m.moving_points
        ('A',)
        """
        seen = dict.fromkeys(p for lk in self.links for p in lk.point_names)
        fixed = self._fixed_points()
        return tuple(p for p in seen if p not in fixed)

    def _fixed_points(self) -> set:
        """The points that do not move: the ground's."""
        return set(dict(self.ground))

    @property
    def mobility(self) -> int:
        """Degrees of freedom counted from the structure (unknowns minus equations).

        Examples
        --------
        >>> from kincas import Input, Link, Mechanism, Param, Slide
        >>> m = Mechanism(parameters={"r": 2.0}, ground={"O": (0, 0)},
        ...     links=[Link.bar("crank", "O", "A", "r")], inputs=[Input.angle("crank")])
        >>> m.mobility
        1
        """
        return self.structure.mobility

    def value(self, v: Num) -> float:
        """The number `v`, resolving a parameter reference.

        Parameters
        ----------
        v : float, str or Param

        Returns
        -------
        float

        Examples
        --------
        >>> from kincas import Input, Link, Mechanism, Param, Slide
        >>> m = Mechanism(parameters={"r": 2.0}, ground={"O": (0, 0)},
        ...     links=[Link.bar("crank", "O", "A", "r")], inputs=[Input.angle("crank")])
        >>> m.value("r"), m.value(Param("r", 0.5)), m.value(3)
        (2.0, 1.0, 3.0)
        """
        p = as_param(v)
        return float(v) if p is None else p.scale * self.param_values[p.name]

    def with_parameters(self, **values: float) -> "Lookups":
        """A new mechanism with some parameters changed.

        Parameters
        ----------
        **values : float
            New values of existing parameters.

        Returns
        -------
        Mechanism or SpatialMechanism
            Of the same kind as this one.

        Examples
        --------
        >>> from kincas import Input, Link, Mechanism, Param, Slide
        >>> m = Mechanism(parameters={"r": 2.0}, ground={"O": (0, 0)},
        ...     links=[Link.bar("crank", "O", "A", "r")], inputs=[Input.angle("crank")])
        >>> m.with_parameters(r=3).size(), m.size()
        (3.0, 2.0)
        """
        problems = [f"[parameters] {k}: no such parameter" for k in values if k not in self.param_values]
        problems += [f"[parameters] {k}: expected a number, got {v!r}" for k, v in values.items()
                     if not is_number(v)]
        if problems:
            raise ModelError(problems)
        return replace(self, parameters={**self.param_values, **{k: float(v) for k, v in values.items()}})
