"""Where each point's name goes in a picture: beside its point, in the freest spot.

For each point, candidate spots lie on two circles around it (radii 3 and 4.5 units of size
r, 16 directions each); the spot chosen is the one farthest from everything drawn at that
pose (bars, bodies' edges, slide blocks and guides, ground symbols, springs, other points
and the names already placed), sampled as points every half unit; ties go to the nearer
circle. A name thus keeps off the blocks it would otherwise cover, in every format (PNG,
GIF, SVG, DXF, HTML).

>>> import numpy as np
>>> xy = np.array([[0.0, 0.0], [10.0, 0.0]])
>>> spots = label_spots(xy, 1.0, segments=[xy])
>>> bool(abs(spots[0][1]) > 2.5)       # off the bar between the two points, above or below it
True
"""
from __future__ import annotations

import numpy as np

_ANGLES = np.linspace(0, 2 * np.pi, 16, endpoint=False) + np.pi / 4  # up-right first on ties
_RING = np.stack([np.cos(_ANGLES), np.sin(_ANGLES)], axis=1)


def _samples(poly: np.ndarray, step: float, closed: bool = False) -> np.ndarray:
    """Points every `step` along a polyline (closed: back to its first point)."""
    poly = np.asarray(poly, float)
    poly = poly[np.isfinite(poly).all(axis=1)]
    if closed and len(poly) > 2:
        poly = np.vstack([poly, poly[:1]])
    if len(poly) < 2:
        return poly.reshape(-1, 2)
    out = [poly[:1]]
    for a, b in zip(poly[:-1], poly[1:]):
        k = max(1, int(np.ceil(np.hypot(*(b - a)) / step)))
        out.append(a + np.outer(np.arange(1, k + 1) / k, b - a))
    return np.concatenate(out)


def label_spots(xy: np.ndarray, r: float, *, segments=(), polygons=(), skip=()) -> np.ndarray:
    """(P x 2) where the names of the P points `xy` go (NaN for an unknown point or one in
    `skip`): away from the polylines `segments` and the closed `polygons` drawn."""
    xy = np.asarray(xy, float)
    step = 0.5 * r
    parts = [_samples(s, step) for s in segments] + [_samples(p, step, True) for p in polygons]
    for p in polygons:  # the inside of a block counts too
        p = np.asarray(p, float)
        if np.isfinite(p).all():
            parts.append(p.mean(axis=0, keepdims=True))
    known = np.isfinite(xy).all(axis=1)
    parts.append(xy[known])
    obstacles = np.concatenate([p for p in parts if p.size] or [np.zeros((0, 2))])
    out = np.full_like(xy, np.nan)
    for k in range(len(xy)):
        if not known[k] or k in skip:
            continue
        cand = np.concatenate([xy[k] + 3.0 * r * _RING, xy[k] + 4.5 * r * _RING])
        near = obstacles[(np.abs(obstacles - xy[k]) < 7.5 * r).all(axis=1)]  # beyond: never the closest
        if len(near):
            diff = cand[:, None, :] - near[None, :, :]
            d = np.sqrt(np.einsum("ijk,ijk->ij", diff, diff).min(axis=1))
        else:
            d = np.full(len(cand), np.inf)
        d = np.minimum(d, 2.5 * r)  # far enough is far enough: then the nearer circle wins
        d[len(_RING):] -= 0.25 * r
        best = cand[int(np.argmax(d))]
        out[k] = best
        obstacles = np.vstack([obstacles, best + 0.8 * r * _RING[::4], best[None]])  # the name now there
    return out


def picture_obstacles(pic, i: int):
    """(segments, polygons) of a `views.picture.Picture` at pose i: what the names avoid."""
    xy = pic.xy[i]
    r = pic.r
    segments, polygons = [], []
    for b in pic.bodies:
        pts = xy[b.ring]
        (polygons if len(b.ring) >= 3 else segments).append(pts)
    for g in pic.guides:
        t, d = g.through[i], g.direction[i]
        if not (np.isfinite(t).all() and np.isfinite(d).all()):
            continue
        segments.append(np.array([t + g.lo * d, t + g.hi * d]))
        p = xy[g.point]
        if np.isfinite(p).all():
            polygons.append(block(p, d, r))
    for k in pic.ground:
        polygons.append(ground_symbol(xy[k], r))
    segments += [zz for _, zz in pic.spring_lines(i)]
    return segments, polygons


def picture_labels(pic, i: int) -> list[tuple[str, np.ndarray, np.ndarray]]:
    """(name, point, offset from the point to its name's centre) of each known point."""
    segments, polygons = picture_obstacles(pic, i)
    xy = pic.xy[i]
    spots = label_spots(xy, pic.r, segments=segments, polygons=polygons)
    return [(name, xy[k], spots[k] - xy[k]) for k, name in enumerate(pic.names) if np.isfinite(spots[k]).all()]


label_offsets = picture_labels  # the DXF writer's name for it


def block(p, d, r) -> np.ndarray:
    """The corners of a slide's block at p along unit d (4 r long, 2.8 r across), as drawn."""
    n = np.array([-d[1], d[0]])
    return np.array([p - 2 * r * d - 1.4 * r * n, p + 2 * r * d - 1.4 * r * n,
                     p + 2 * r * d + 1.4 * r * n, p - 2 * r * d + 1.4 * r * n])


def ground_symbol(p, r) -> np.ndarray:
    """The triangle under a ground pivot, as drawn (with its hatched base)."""
    h = 2.5 * r
    x, y = p
    return np.array([(x, y), (x - 1.1 * h, y - 1.35 * h), (x + 1.1 * h, y - 1.35 * h)])
