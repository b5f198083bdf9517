"""The Assur-group structure of g_q (kincas/core/structure.py) and each group's own scale.

The expected groups are found here independently of kincas's equations, from the topology
alone: an Assur group is a smallest set of links that, with everything placed before it
held fixed, has zero degrees of freedom by Gruebler's count (3 per link, 2 per pin joint,
1 per slide, 1 per input acting on it). Peeling such sets off one after another decomposes
the chain; each group that has unknowns must be exactly one block of `model.blocks`.
"""
from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from conftest import EXAMPLES

import kincas
from kincas.cli.scene import load
from kincas.model import GROUND

# planar Assur groups; a spatial model's blocks are its bodies' (tests/test_space*.py)
# spatial scenes have their own structure tests; a lone flywheel crank has no loop to split
SHIPPED = sorted(p for p in EXAMPLES.glob("*.toml") if not p.stem.startswith(("space_", "simulate_space_"))
                 and p.stem != "simulate_flywheel_textbook")


# --- Assur groups by Gruebler's count over subsets of links ---


def _mobility(m, group: set[str], fixed: set[str]) -> int:
    """Degrees of freedom of `group` with the bodies in `fixed` (and the ground) held."""
    bodies = {lk.name: set(lk.point_names) for lk in m.links}
    fixed_pts = set(m.ground_points).union(*(bodies[b] for b in fixed)) if fixed else set(m.ground_points)
    pts = set().union(*(bodies[b] for b in group))
    joints = 0
    for p in pts:  # a point shared by k bodies is k - 1 pin joints
        k = sum(p in bodies[b] for b in group) + (p in fixed_pts)
        joints += k - 1
    placed = group | fixed
    here = pts | fixed_pts
    slides = [s for s in m.slides if (s.along in placed or s.along == GROUND) and s.point in here
              and (s.along in group or s.point in pts)]
    inputs = sum(1 for i in m.inputs if i.kind == "angle" and i.target in group)
    inputs += sum(1 for i in m.inputs if i.kind == "slide" and i.target in {s.name for s in slides})
    return 3 * len(group) - 2 * joints - len(slides) - inputs


def assur_groups(m) -> list[frozenset[str]]:
    fixed: set[str] = set()
    left = [lk.name for lk in m.links]
    groups = []
    while left:
        found = None
        for n in range(1, len(left) + 1):
            for c in itertools.combinations(left, n):
                if _mobility(m, set(c), fixed) == 0:
                    found = set(c)
                    break
            if found:
                break
        assert found, f"no group among {left}"
        groups.append(frozenset(found))
        fixed |= found
        left = [x for x in left if x not in found]
    return groups


def unknown_links(model, cols) -> frozenset[str]:
    return frozenset(model.sym.unknowns[j][0].split(".")[0] for j in cols)


# --- every example's groups ---


@pytest.mark.parametrize("path", SHIPPED, ids=lambda p: p.stem)
def test_blocks_are_the_assur_groups(path):
    m = load(path).mechanism
    model = kincas.model_of(m)
    # the count above knows pins, slides and absolute inputs only: with gears, racks, cams
    # or relative inputs, only the blocks' own properties below are checked
    if not (m.gears or m.racks or m.cams or any("/" in i.target for i in m.inputs)):
        expected = [g for g in assur_groups(m) if model.nq and any(
            name.split(".")[0] in g for name, _ in model.sym.unknowns)]
        got = [unknown_links(model, b.cols) for b in model.blocks]
        assert sorted(map(sorted, got)) == sorted(map(sorted, expected))
    # every unknown and equation in exactly one block, square blocks
    assert sorted(np.concatenate([b.cols for b in model.blocks]).tolist()) == list(range(model.nq))
    assert sorted(np.concatenate([b.rows for b in model.blocks]).tolist()) == list(range(model.ng))
    assert all(b.rows.size == b.cols.size == b.size for b in model.blocks)
    # solve order: block i's equations do not involve unknowns of later blocks (g_q at a
    # random point is exactly zero there)
    rng = np.random.default_rng(0)
    p = np.array([v for _, v in m.parameters])
    J = model.jac(rng.standard_normal(model.nq), rng.standard_normal(model.nu), p)
    for i, bi in enumerate(model.blocks):
        assert np.linalg.matrix_rank(J[np.ix_(bi.rows, bi.cols)]) == bi.size
        for bj in model.blocks[i + 1:]:
            assert not np.any(J[np.ix_(bi.rows, bj.cols)])


def test_triad_and_class_four_group_are_one_block_each():
    triad = kincas.model_of(load(EXAMPLES / "assur_triad.toml").mechanism)
    # legs 1-3 and the plate: four angles, two closures of two equations
    assert [(b.size, b.links) for b in triad.blocks] == [(4, ("leg1", "leg2", "leg3", "plate"))]
    eight = kincas.model_of(load(EXAMPLES / "eightbar.toml").mechanism)
    # the class-IV group (lever, PR, floater, QS) before the dyad that it drives (rod, rocker)
    assert [(b.size, b.links) for b in eight.blocks] == [
        (4, ("floater", "lever", "link1", "link2")), (2, ("rocker", "rod"))]


def _chain(n: int) -> kincas.Mechanism:
    """n four-bars in series: the rocker of each is the crank of the next."""
    ground = {f"A{k}": (4.0 * k, 0.0) for k in range(n + 1)}
    links = [kincas.Link.bar("crank0", "A0", "B0", 1)]
    for k in range(n):
        links += [kincas.Link.bar(f"coupler{k}", f"B{k}", f"C{k}", 3.5),
                  kincas.Link(f"rocker{k}", {f"A{k + 1}": (0, 0), f"C{k}": (3, 0), f"B{k + 1}": (0, 1)})]
    return kincas.Mechanism(ground=ground, links=links, inputs=[kincas.Input.angle("crank0")])


def test_chained_fourbars_are_dyads_in_order():
    n = 6
    model = kincas.model_of(_chain(n))
    assert [b.links for b in model.blocks] == [(f"coupler{k}", f"rocker{k}") for k in range(n)]
    assert [b.size for b in model.blocks] == [2] * n


# --- scales from each group's own geometry ---


def _fourbar(extra=None):
    ground = {"A": (0, 0), "D": (4, 0)}
    links = [kincas.Link.bar("crank", "A", "B", 1), kincas.Link.bar("coupler", "B", "C", 3.5),
             kincas.Link.bar("rocker", "D", "C", 3)]
    if extra:
        ground["Far"] = extra
    return kincas.Mechanism(ground=ground, links=links, inputs=[kincas.Input.angle("crank")],
                            guess={"C": (3.6, 2.9)})


def test_scales_come_from_the_group_not_the_drawing():
    near, far = _fourbar(), _fourbar((1e5, 0))
    assert far.size() > 1e4  # the whole drawing is huge ...
    for m in (near, far):
        model = kincas.model_of(m)
        eq, qs = model.scales(np.array([0.3]), np.zeros(0))
        # ... but the dyad's loop A-B-C-D is measured by its own longest body, the coupler
        assert np.all(eq == 3.5) and eq.shape == (model.ng,)
        assert np.all(qs == 1.0) and qs.shape == (model.nq,)  # both unknowns are angles


def test_length_unknowns_scale_with_their_group():
    # a Scotch yoke: the yoke floats (x, y and angle unknown), held on the ground line by P
    # and Q, and the crank pin B runs in its vertical slot
    m = kincas.Mechanism(
        ground={"A": (0, 0), "Far": (-1e6, 0)},
        links=[kincas.Link.bar("crank", "A", "B", 1), kincas.Link("yoke", {"P": (0, 0), "Q": (5, 0)})],
        slides=[kincas.Slide("P", "ground"), kincas.Slide("Q", "ground"),
                kincas.Slide("B", "yoke", angle=math.pi / 2, name="slot")],
        inputs=[kincas.Input.angle("crank")], guess={"P": (0.5, 0), "Q": (5.5, 0)})
    model = kincas.model_of(m)
    # (its equations are triangular: P's height gives y, Q's the angle, the slot x)
    assert [b.links for b in model.blocks] == [("yoke",)] * 3
    eq, qs = model.scales(np.array([0.3]), np.zeros(0))
    assert np.all(eq == 5.0)  # the yoke's length, not the million of the far point
    for (name, kind), s in zip(model.sym.unknowns, qs):
        assert s == (5.0 if kind == "length" else 1.0), name
    assert sorted(k for _, k in model.sym.unknowns) == ["angle", "length", "length"]
