"""The checks of a spatial mechanism's declaration, every problem gathered and named by its
section and field (no casadi here): a part of `kincas.SpatialMechanism` (kincas/model/space.py).

>>> from kincas.model.space import SpatialMechanism
>>> SpatialMechanism(ground={"A": (0, 0, 0)}).ground_points
('A',)
"""
from __future__ import annotations

from dataclasses import replace

from ..errors import ModelError
from .checks import _number_check
from .mobility import GROUND
from .space_parts import _triple


class SpatialChecks:
    """Checks of a `SpatialMechanism`'s parts (the fields are the dataclass's)."""

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
            if p in ground and p not in self.moving_points:  # (a slide joint's point moves)
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
