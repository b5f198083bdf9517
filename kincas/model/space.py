"""Declarations of a spatial mechanism as an immutable value (no casadi here).

A spatial mechanism is ground points, bodies drawn in one assembled pose (global
coordinates), two-point bars, joints (a point shared by two bodies is a ball joint unless a
`Joint` there says otherwise), slides on lines and planes, and inputs: joint coordinates
(`Input.joint("A")`), slides and parameters. Angles are radians in Python. kincas.core builds
its equations (kincas/core/space_symbolic.py); docs/spatial.md says how and why.

>>> m = SpatialMechanism(
...     ground={"A": (0, 0, 0), "D": (120, 40, 30)},
...     bodies=[Body("crank", {"A": (0, 0, 0), "B": (25, 0, 0)}), Body.bar("coupler", "B", "C", 130),
...             Body("rocker", {"D": (120, 40, 30), "C": (120, 40, 90)})],
...     joints=[Joint("revolute", "A", axis=(0, 0, 1)), Joint("revolute", "D", axis=(1, 0, 0))],
...     inputs=[Input.joint("A")])
>>> m.inputs[0].key, m.mobility, m.moving_points
('A.angle', 1, ('B', 'C'))
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

from ..errors import ModelError
from .checks import _number_check
from .mobility import GROUND, Structure
from .parts import Input, Num, as_param, is_number
from .space_parts import ON_SECOND, Body, Joint, SpatialSlide, _triple  # noqa: F401
from .values import _table

SPACE = "3d"


@dataclass(frozen=True)
class SpatialMechanism:
    """A spatial mechanism (`space = "3d"`): an immutable value, checked on construction.

    Every problem found is gathered into one `ModelError`. The drawing pose is the default
    guess: `guess` moves points away from it (and places points that only bars carry).

    Parameters
    ----------
    parameters : dict
        Named numbers that coordinates and lengths may refer to by name.
    ground : dict
        Ground points: name -> (x, y, z).
    bodies : sequence of Body
        Rigid bodies (`Body(name, points)`) and two-point bars (`Body.bar`).
    joints : sequence of Joint
    slides : sequence of SpatialSlide
    inputs : sequence of Input
        `Input.joint("J")` / `Input.joint("J.angle1")`, `Input.slide`, `Input.parameter`.
    guess : dict
        Point -> (x, y, z): where points are near at the first pose.

    Examples
    --------
    >>> m = SpatialMechanism(ground={"O": (0, 0, 0)},
    ...     bodies=[Body("arm", {"O": (0, 0, 0), "P": (1, 0, 0)})],
    ...     joints=[Joint("revolute", "O", axis=(0, 0, 1))], inputs=[Input.joint("O")])
    >>> m.size(), m.with_parameters().guess
    (1.0, (('P', (1, 0, 0)),))
    """

    parameters: tuple = ()
    ground: tuple = ()
    bodies: tuple = ()
    joints: tuple = ()
    slides: tuple = ()
    inputs: tuple = ()
    guess: tuple = ()
    gravity: tuple = (0.0, 0.0, 0.0)
    loads: tuple = ()
    structure: Structure = field(init=False, repr=False, compare=False)

    space = SPACE
    gears = racks = cams = ()  # planar joints: none in space

    def __post_init__(self):
        put = lambda k, v: object.__setattr__(self, k, v)
        params = []
        for k, v in _table(self.parameters, "parameters", "number"):
            if not is_number(v):
                raise ModelError(f"[parameters] {k}: expected a number, got {v!r}")
            params.append((k, float(v)))
        put("parameters", tuple(params))
        put("ground", tuple((k, _triple(v, f"[ground] {k}")) for k, v in _table(self.ground, "ground", "(x, y, z)")))
        for f, kind in (("bodies", Body), ("joints", Joint), ("slides", SpatialSlide), ("inputs", Input)):
            items = tuple(getattr(self, f))
            bad = [f"{f}[{i}]: expected a kincas.{kind.__name__}, got {x!r:.60}"
                   for i, x in enumerate(items) if not isinstance(x, kind)]
            if bad:
                raise ModelError(bad)
            put(f, items)
        put("gravity", _triple(self.gravity, "gravity"))
        put("loads", tuple(self._load(k, ld) for k, ld in enumerate(self.loads)))
        given = tuple((k, _triple(v, f"[guess] {k}")) for k, v in _table(self.guess, "guess", "(x, y, z)"))
        problems = self._check(given)
        if problems:
            raise ModelError(problems)
        put("inputs", tuple(self._resolve(i) for i in self.inputs))
        # the drawing pose is the default guess; [guess] moves points away from it
        drawn = dict(self._drawn())
        put("guess", tuple({**drawn, **dict(given)}.items()))
        nq, ng = self.counts()
        put("structure", Structure((), (), (), nq, ng))
        from .mobility import _check_mobility
        problems = _check_mobility(self)
        if problems:
            raise ModelError(problems)

    def _load(self, k, ld):
        """A load with its force or torque as a triple (kincas.Load, 3D values)."""
        from .loads import Load
        where = f"[[loads]] {k + 1}"
        if not isinstance(ld, Load):
            raise ModelError(f"{where}: expected a kincas.Load, got {ld!r:.60}")
        if ld.kind in ("force", "torque"):
            return replace(ld, value=_triple(ld.value, f"{where}: {ld.kind}"))
        return ld

    # --- checks ---
    def _check(self, given) -> list[str]:
        out: list[str] = []
        num = _number_check(dict(self.parameters), out)
        names = [GROUND]
        for b in self.bodies:
            if b.name in names:
                out.append(f"[links] {b.name}: the name is used twice (or is reserved)")
            names.append(b.name)
            for p, xyz in b.points:
                for c in xyz or ():
                    num(f"[links] {b.name}: points.{p}", c)
            if b.two_point:
                num(f"[links] {b.name}: length", b.length)
        for g, xyz in self.ground:
            for c in xyz:
                num(f"[ground] {g}", c)
        for b in self.bodies:
            where = f"[links] {b.name}"
            num(f"{where}: mass", b.mass)
            for c in (b.cg or ()):
                num(f"{where}: cg", c)
            for c in b.inertia:
                num(f"{where}: inertia", c)
            if b.two_point and (b.cg is not None or any(c != 0 for c in b.inertia)):
                out.append(f"{where}: a two-point bar takes a mass only (at its middle; no cg, no inertia)")
        for c in self.gravity:
            num("gravity", c)
        rigid = {b.name for b in self.bodies if not b.two_point}
        known = {p for b in self.bodies for p in b.point_names} | set(dict(self.ground))
        for k, ld in enumerate(self.loads):
            where = f"[[loads]] {k + 1}"
            if ld.kind == "force" and ld.at not in known:
                out.append(f"{where}: point: unknown point {ld.at!r}")
            elif ld.kind == "torque" and ld.at not in rigid:
                out.append(f"{where}: link: {ld.at!r} is not a rigid body (a torque needs one)")
            elif ld.kind == "spring":
                out += [f"{where}: spring: unknown point {p!r}" for p in ld.points if p not in known]
                num(f"{where}: stiffness", ld.stiffness), num(f"{where}: free_length", ld.free_length)
            for c in (ld.value if ld.kind != "spring" else ()):
                num(f"{where}: {ld.kind}", c)
        bodies = {b.name: b for b in self.bodies}
        carried = {p for b in self.bodies for p in b.point_names}
        for j in self.joints:
            where = f"[[joints]] {j.name}"
            try:
                first, second = self.joint_bodies(j)
            except ModelError as e:
                out += e.problems
                continue
            for b in (first, second):
                if b != GROUND and bodies[b].two_point and j.type != "spherical":
                    out.append(f"{where}: bodies: {b!r} is a two-point bar: it cannot carry a "
                               f"{j.type} joint (its spin is not a freedom); make it a body "
                               f"with its points drawn")
        jn = [j.name for j in self.joints]
        out += [f"[[joints]] {n}: name: used twice" for n in sorted({n for n in jn if jn.count(n) > 1})]
        for s in self.slides:
            where = f"[[slides]] {s.name}"
            if s.along != GROUND and s.along not in bodies:
                out.append(f"{where}: along: unknown body {s.along!r}")
            elif s.along != GROUND and bodies[s.along].two_point:
                out.append(f"{where}: along: {s.along!r} is a two-point bar (it has no frame to slide on)")
            if s.point not in carried:
                out.append(f"{where}: point: {s.point!r} is not a point of any body")
            for c in s.through:
                num(f"{where}: through", c)
        ground = dict(self.ground)
        drawn = {p for b in self.bodies if not b.two_point for p in b.point_names} | set(ground)
        for p, xyz in given:
            if p in ground:
                out.append(f"[guess] {p}: is a ground point (fixed)")
            elif p not in carried:
                out.append(f"[guess] {p}: is not a point of any body")
            for c in xyz:
                num(f"[guess] {p}", c)
        gv = dict(given)
        for b in self.bodies:
            for p in b.point_names:
                if p not in drawn and p not in gv:
                    out.append(f"[guess] {p}: missing: a point carried only by two-point bars has "
                               f"no drawn position (give it, P = [x, y, z])")
                    drawn.add(p)
        for k, i in enumerate(self.inputs):
            where = f"[[inputs]] {k + 1}"
            if i.kind == "joint":
                try:
                    self._resolve(i)
                except ModelError as e:
                    out += e.problems
            elif i.kind == "slide":
                if i.target not in {s.name for s in self.slides if s.on_line}:
                    out.append(f"{where}: slide: {i.target!r} is not a slide on a line")
            elif i.kind == "parameter":
                if i.target not in dict(self.parameters):
                    out.append(f"{where}: parameter: unknown parameter {i.target!r}")
            else:
                out.append(f"{where}: a spatial mechanism is driven by joint, slide or parameter "
                           f"inputs (got {i.kind!r}: use joint = \"J\")")
        keys = [i.key for i in self.inputs if i.kind != "joint" or "." in i.target]
        out += [f"[[inputs]] {k}: driven twice" for k in sorted({k for k in keys if keys.count(k) > 1})]
        return out

    def joint_bodies(self, j: Joint) -> tuple[str, str]:
        """(first, second) body of a joint: its `bodies`, else the two bodies (the ground
        counting as one; never a bar) that carry its point, the ground first, else in
        declaration order; for a joint whose point belongs to its second body only
        (cylindrical, prismatic, planar), a point on one body alone pairs it with the ground.

        Parameters
        ----------
        j : Joint

        Returns
        -------
        (str, str)

        Examples
        --------
        >>> m = SpatialMechanism(ground={"O": (0, 0, 0)}, bodies=[Body("arm", {"O": (0, 0, 0), "P": (1, 0, 0)})],
        ...     joints=[Joint("revolute", "O", axis=(0, 0, 1))], inputs=[Input.joint("O")])
        >>> m.joint_bodies(m.joint("O"))
        ('ground', 'arm')
        """
        where = f"[[joints]] {j.name}"
        names = {b.name for b in self.bodies} | {GROUND}
        if j.bodies is not None:
            bad = [b for b in j.bodies if b not in names]
            if bad:
                raise ModelError(f"{where}: bodies: unknown body {bad[0]!r}")
            return j.bodies
        on = ([GROUND] if j.point in dict(self.ground) else []) + [
            b.name for b in self.bodies if not b.two_point and j.point in b.point_names]
        if len(on) == 1 and j.type in ON_SECOND and on[0] != GROUND:
            return GROUND, on[0]
        if len(on) != 2:
            raise ModelError(f"{where}: bodies: {len(on)} bodies carry point {j.point!r} "
                             f"({', '.join(on) or 'none'}); name the two: bodies = [\"first\", \"second\"]")
        return on[0], on[1]

    def _resolve(self, i: Input) -> Input:
        """A joint input keyed by its coordinate: "A" -> "A.angle" (a one-coordinate joint)."""
        if i.kind != "joint":
            return i
        jname, _, coord = i.target.partition(".")
        joints = {j.name: j for j in self.joints}
        where = f"[[inputs]] {i.target}"
        if jname not in joints:
            raise ModelError(f"{where}: joint: unknown joint {jname!r} (joints are named by "
                             f"`name`, default their point)")
        coords = joints[jname].coordinates
        if not coord:
            if len(coords) != 1:
                raise ModelError(f"{where}: joint: a {joints[jname].type} joint has coordinates "
                                 f"{list(coords)}: name one, e.g. \"{jname}.{(coords or ('angle',))[0]}\"")
            coord = coords[0]
        if coord not in coords:
            raise ModelError(f"{where}: joint: a {joints[jname].type} joint has no coordinate "
                             f"{coord!r} (it has {list(coords)})")
        return Input("joint", f"{jname}.{coord}")

    # --- counts ---
    def counts(self) -> tuple[int, int]:
        """(unknowns, equations without the inputs'): 7 per body (its reference point and
        unit quaternion), 3 per point only bars carry; 1 per body (the quaternion's norm),
        3 per extra carrier of a point, 1 per bar, and each joint's and slide's own.

        Examples
        --------
        >>> m = SpatialMechanism(ground={"O": (0, 0, 0)}, bodies=[Body("arm", {"O": (0, 0, 0), "P": (1, 0, 0)})],
        ...     joints=[Joint("revolute", "O", axis=(0, 0, 1))], inputs=[Input.joint("O")])
        >>> m.counts()  # 7 unknowns; the norm, the point, the axis: 6 equations
        (7, 6)
        """
        rigid = [b for b in self.bodies if not b.two_point]
        on_body = {p for b in rigid for p in b.point_names} | set(dict(self.ground))
        free_pts = {p for b in self.bodies for p in b.point_names} - on_body
        nq = 7 * len(rigid) + 3 * len(free_pts)
        ng = len(rigid) + sum(b.two_point for b in self.bodies)
        exempt = self.exempt()
        for p in on_body:
            carriers = ([GROUND] if p in dict(self.ground) else []) + [
                b.name for b in rigid if p in b.point_names and (p, b.name) not in exempt]
            ng += 3 * max(len(carriers) - 1, 0)
        extra = {"spherical": 0, "revolute": 2, "universal": 1, "cylindrical": 4,
                 "prismatic": 5, "planar": 3}
        ng += sum(extra[j.type] for j in self.joints)
        ng += sum(2 if s.on_line else 1 for s in self.slides)
        return nq, ng

    def exempt(self) -> set:
        """(point, body): a first body's copy of a point that belongs to the second body of
        its cylindrical, prismatic or planar joint (the joint's own equations hold it).

        Examples
        --------
        >>> m = SpatialMechanism(ground={"O": (0, 0, 0)}, bodies=[Body("arm", {"O": (0, 0, 0), "P": (1, 0, 0)})],
        ...     joints=[Joint("revolute", "O", axis=(0, 0, 1))], inputs=[Input.joint("O")])
        >>> m.exempt()
        set()
        """
        out = set()
        for j in self.joints:
            if j.type in ON_SECOND:
                try:
                    out.add((j.point, self.joint_bodies(j)[0]))
                except ModelError:
                    pass
        return out

    # --- lookups, as a planar Mechanism answers them ---
    @property
    def links(self) -> tuple:
        """The bodies and bars (named like a planar mechanism's links).

        Examples
        --------
        >>> m = SpatialMechanism(ground={"O": (0, 0, 0)}, bodies=[Body("arm", {"O": (0, 0, 0), "P": (1, 0, 0)})],
        ...     joints=[Joint("revolute", "O", axis=(0, 0, 1))], inputs=[Input.joint("O")])
        >>> [b.name for b in m.links]
        ['arm']
        """
        return self.bodies

    @property
    def redundant(self) -> int:
        """Equations implied by the others (Bennett's, Bricard's linkage): decided by the
        constraint Jacobian's rank at generic assemblies, whatever the guess (as
        `Mechanism.redundant`).

        Examples
        --------
        >>> SpatialMechanism(ground={"O": (0, 0, 0)}, bodies=[Body.bar("b", "O", "P", 1)],
        ...     guess={"P": (1, 0, 0)}, inputs=[]).redundant
        0
        """
        from .mechanism import Mechanism
        return Mechanism.redundant.fget(self)

    @property
    def param_values(self) -> dict[str, float]:
        """The parameters as a dict.

        Examples
        --------
        >>> m = SpatialMechanism(ground={"O": (0, 0, 0)}, bodies=[Body("arm", {"O": (0, 0, 0), "P": (1, 0, 0)})],
        ...     joints=[Joint("revolute", "O", axis=(0, 0, 1))], inputs=[Input.joint("O")])
        >>> m.param_values
        {}
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
        >>> m = SpatialMechanism(ground={"O": (0, 0, 0)}, bodies=[Body("arm", {"O": (0, 0, 0), "P": (1, 0, 0)})],
        ...     joints=[Joint("revolute", "O", axis=(0, 0, 1))], inputs=[Input.joint("O")])
        >>> m.with_parameters() and SpatialMechanism(parameters={"r": 2.0}).parameter("r")
        2.0
        """
        return self.param_values[name]

    def link(self, name: str) -> Body:
        """The body of that name.

        Parameters
        ----------
        name : str

        Returns
        -------
        Body

        Examples
        --------
        >>> m = SpatialMechanism(ground={"O": (0, 0, 0)}, bodies=[Body("arm", {"O": (0, 0, 0), "P": (1, 0, 0)})],
        ...     joints=[Joint("revolute", "O", axis=(0, 0, 1))], inputs=[Input.joint("O")])
        >>> m.link("arm").point_names
        ('O', 'P')
        """
        return {b.name: b for b in self.bodies}[name]

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
        >>> m = SpatialMechanism(ground={"O": (0, 0, 0)}, bodies=[Body("arm", {"O": (0, 0, 0), "P": (1, 0, 0)})],
        ...     joints=[Joint("revolute", "O", axis=(0, 0, 1))], inputs=[Input.joint("O")])
        >>> m.joint("O").type
        'revolute'
        """
        return {j.name: j for j in self.joints}[name]

    def slide(self, name: str) -> SpatialSlide:
        """The slide of that name.

        Parameters
        ----------
        name : str

        Returns
        -------
        SpatialSlide

        Examples
        --------
        >>> m = SpatialMechanism(ground={"O": (0, 0, 0)}, bodies=[Body("arm", {"O": (0, 0, 0), "P": (1, 0, 0)})],
        ...     joints=[Joint("revolute", "O", axis=(0, 0, 1))], inputs=[Input.joint("O")])
        >>> SpatialMechanism(ground={"O": (0, 0, 0)}, bodies=[Body.bar("b", "O", "P", 1)], slides=[SpatialSlide("P", "ground", (0, 0, 0), normal=(0, 0, 1))], guess={"P": (1, 0, 0)}).slide("P").on_line
        False
        """
        return {s.name: s for s in self.slides}[name]

    @property
    def ground_points(self) -> tuple[str, ...]:
        """The ground points' names.

        Examples
        --------
        >>> m = SpatialMechanism(ground={"O": (0, 0, 0)}, bodies=[Body("arm", {"O": (0, 0, 0), "P": (1, 0, 0)})],
        ...     joints=[Joint("revolute", "O", axis=(0, 0, 1))], inputs=[Input.joint("O")])
        >>> m.ground_points
        ('O',)
        """
        return tuple(g for g, _ in self.ground)

    @property
    def moving_points(self) -> tuple[str, ...]:
        """Points carried by bodies and not fixed to the ground, in declaration order.

        Examples
        --------
        >>> m = SpatialMechanism(ground={"O": (0, 0, 0)}, bodies=[Body("arm", {"O": (0, 0, 0), "P": (1, 0, 0)})],
        ...     joints=[Joint("revolute", "O", axis=(0, 0, 1))], inputs=[Input.joint("O")])
        >>> m.moving_points
        ('P',)
        """
        seen = dict.fromkeys(p for b in self.bodies for p in b.point_names)
        return tuple(p for p in seen if p not in dict(self.ground))

    @property
    def mobility(self) -> int:
        """Degrees of freedom counted (unknowns minus equations).

        Examples
        --------
        >>> m = SpatialMechanism(ground={"O": (0, 0, 0)}, bodies=[Body("arm", {"O": (0, 0, 0), "P": (1, 0, 0)})],
        ...     joints=[Joint("revolute", "O", axis=(0, 0, 1))], inputs=[Input.joint("O")])
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
        >>> m = SpatialMechanism(ground={"O": (0, 0, 0)}, bodies=[Body("arm", {"O": (0, 0, 0), "P": (1, 0, 0)})],
        ...     joints=[Joint("revolute", "O", axis=(0, 0, 1))], inputs=[Input.joint("O")])
        >>> SpatialMechanism(parameters={"r": 2.0}).value("r")
        2.0
        """
        p = as_param(v)
        return float(v) if p is None else p.scale * self.param_values[p.name]

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
        >>> SpatialMechanism(parameters={"r": 2.0}, ground={"O": (0, 0, 0)}, bodies=[Body.bar("b", "O", "P", "r")],
        ...     guess={"P": (2, 0, 0)}).sizes([[3.0], [4.0]], ["r"]).tolist()
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

    def with_parameters(self, **values: float) -> "SpatialMechanism":
        """A new mechanism with some parameters changed.

        Parameters
        ----------
        **values : float

        Returns
        -------
        SpatialMechanism

        Examples
        --------
        >>> m = SpatialMechanism(ground={"O": (0, 0, 0)}, bodies=[Body("arm", {"O": (0, 0, 0), "P": (1, 0, 0)})],
        ...     joints=[Joint("revolute", "O", axis=(0, 0, 1))], inputs=[Input.joint("O")])
        >>> SpatialMechanism(parameters={"r": 2.0}).with_parameters(r=3).parameter("r")
        3.0
        """
        bad = [f"[parameters] {k}: no such parameter" for k in values if k not in self.param_values]
        bad += [f"[parameters] {k}: expected a number" for k, v in values.items() if not is_number(v)]
        if bad:
            raise ModelError(bad)
        return replace(self, parameters={**self.param_values, **{k: float(v) for k, v in values.items()}})

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
        >>> m = SpatialMechanism(ground={"O": (0, 0, 0)}, bodies=[Body("arm", {"O": (0, 0, 0), "P": (1, 0, 0)})],
        ...     joints=[Joint("revolute", "O", axis=(0, 0, 1))], inputs=[Input.joint("O")])
        >>> dict(m.with_guess(P=(0, 1, 0)).guess)["P"]
        (0, 1, 0)
        """
        return replace(self, guess={**dict(self.guess), **points})

