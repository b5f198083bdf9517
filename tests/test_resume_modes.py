"""Issue [9]: the mode of a group larger than a dyad when a sweep resumes after a gap.

A dyad's mode is the sign of its block's determinant; a class-III triad has up to six
assemblies and the sign cannot tell those of one sign apart. A resume label must be right
("same" only where the assembly is the one left, "other" only where it is not) or say that
the mode could not be established ("unknown"); a change of assembly is never silent.

The reference is independent of kincas: the triad's assemblies by a bracketing search of its
closure residual over the plate angle (`triad_assemblies` of test_class3.py). For leg 3 between
1.6 and 2.5 the triad of examples/assur_triad.toml has two pairs of assemblies, each pair
meeting at a limit of its own: pair A (plate angle near -0.2 rad) at leg 3 = 1.62, pair B
(near 1.6 rad) at 1.87. An assembly's mode is its pair and its rank in the pair (the two
members of a pair meet only at its limit), both continuous in leg 3 while the pair exists.
"""
import numpy as np
import pytest

import kincas
from test_class3 import triad_assemblies, triad_mechanism


def mode_of(phi, r3):
    """(pair, rank) of the independent assembly whose plate angle is phi at leg 3 = r3."""
    found = sorted(a["phi"] for a in triad_assemblies(r3, n=40_001))
    d = np.abs(np.array(found) - phi)
    k = int(np.argmin(d))
    assert d[k] <= 1e-9, (phi, r3, found)  # kincas's assembly is a real one
    pair = "A" if found[k] < 0.5 else "B"
    members = [f for f in found if (f < 0.5) == (pair == "A")]
    return pair, members.index(found[k]) if len(members) == 2 else None


def sweep(r3, start):
    """The sweep from the assembly `start` (a dict of the plate's points) at r3[0]."""
    m = triad_mechanism().with_guess(**{p: tuple(start[p]) for p in ("B1", "B2", "B3")})
    return kincas.sweep(m, {"r3": np.asarray(r3, float)}, report=["plate.angle", "B1.x", "B1.y"])


def check_labels(sw, r3):
    """Every change of mode between consecutive solved poses carries a resume event that is
    not "same"; every "same" is the same mode, every "other" another. Returns the labels."""
    ok = np.flatnonzero(sw.ok)
    truth = {k: mode_of(sw["plate.angle"][k], r3[k]) for k in ok}
    labels = {}
    for e in sw.events:
        if e["kind"] == "resume":
            labels[e["pose"]] = e
    for j, k in zip(ok[:-1], ok[1:]):
        same = truth[j] == truth[k] and truth[k][1] is not None
        e = labels.get(k)
        if not same:
            assert e is not None, f"pose {k}: {truth[j]} -> {truth[k]} with no event"
            assert e["branch"] in ("other", "unknown"), (k, truth[j], truth[k], e)
        elif e is not None:
            assert e["branch"] in ("same", "unknown"), (k, truth[j], truth[k], e)
        if e is not None and e["branch"] == "unknown":
            assert e["unknown"] == [["leg1", "leg2", "leg3", "plate"]] and e["reason"]
    return labels


@pytest.fixture(scope="module")
def pair_b():
    """The two members of pair B at leg 3 = 2.5."""
    return [a for a in triad_assemblies(2.5, n=40_001) if a["phi"] > 1.0]


@pytest.mark.parametrize("member", [0, 1])
def test_resume_on_another_pair_with_the_same_sign_is_not_called_same(pair_b, member):
    # Down in pair B, through a gap (no assembly at all at 1.0 and 0.5), back up to 1.75,
    # where only pair A assembles: kincas resumes on pair A's member of the sign it left.
    # That is not the mode left (pair B has no assembly there): labelled "same" before.
    r3 = np.array([2.5, 2.2, 1.9, 1.0, 0.5, 1.75, 2.0])
    sw = sweep(r3, pair_b[member])
    assert list(sw.ok) == [True, True, True, False, False, True, True]
    assert mode_of(sw["plate.angle"][5], 1.75)[0] == "A"
    labels = check_labels(sw, r3)
    assert labels[5]["branch"] in ("other", "unknown")


@pytest.mark.parametrize("member", [0, 1])
def test_resume_back_through_the_same_limit_is_the_same_mode(pair_b, member):
    # Down into the gap and back the same way: the pair comes back through the limit it left
    # by, where its two members meet; the sign tells them apart, so "same" is proven.
    r3 = np.array([2.5, 2.2, 1.9, 1.0, 1.9, 2.2])
    sw = sweep(r3, pair_b[member])
    assert list(sw.ok) == [True, True, True, False, True, True]
    labels = check_labels(sw, r3)
    assert labels[4]["branch"] == "same"
    assert mode_of(sw["plate.angle"][4], 1.9) == mode_of(sw["plate.angle"][2], 1.9)


def test_mode_ending_at_a_limit_is_never_silently_replaced(pair_b):
    # Down in 0.1 steps: pair B ends at its limit (1.87) while pair A still assembles.
    # Taking pair A's member of the same sign there is a change of mode: said, not silent.
    # Then pair A ends (1.62), a gap, and back up the same way: through pair A's limit.
    r3 = np.round(np.r_[np.arange(2.5, 1.25, -0.1), np.arange(1.4, 2.51, 0.1)], 12)
    sw = sweep(r3, pair_b[0])
    labels = check_labels(sw, r3)
    assert sorted((k, e["branch"]) for k, e in labels.items()) == [(7, "unknown"), (16, "same")]


def test_triad_carried_through_a_gap_of_a_later_dyad_resumes_same():
    # A dyad hung on the plate's corner B3 loses its assembly in the middle of the sweep
    # while the triad assembles throughout: the triad is continued through the gap, so its
    # mode after it is known (the same), and the dyad's by its sign.
    base = triad_mechanism()
    r3 = np.arange(12.0, 19.01, 0.5)
    ref = [max(triad_assemblies(r, n=20_001), key=lambda a: a["B2"][0]) for r in r3]
    B3 = np.array([a["B3"] for a in ref])  # the mode of the example's guess (plate up, right)
    mid = len(r3) // 2
    t = B3[mid + 1] - B3[mid - 1]
    G = B3[mid] + 0.5 * np.array([-t[1], t[0]]) / np.linalg.norm(t)
    d = np.linalg.norm(B3 - G, axis=1)
    arm, rod = 1.5, 1.5 + 0.97 * min(d[0], d[-1])  # no assembly where |B3 - G| < rod - arm
    e = (G - B3[0]) / d[0]
    x = (rod * rod - arm * arm + d[0] ** 2) / (2 * d[0])
    F0 = B3[0] + x * e + np.sqrt(rod * rod - x * x) * np.array([-e[1], e[0]])
    m = kincas.Mechanism(ground={**dict(base.ground), "G": tuple(G)},
                         links=list(base.links) + [kincas.Link.bar("rod", "B3", "F", rod),
                                                   kincas.Link.bar("arm", "G", "F", arm)],
                         inputs=list(base.inputs), parameters=dict(base.parameters),
                         guess={**{p: tuple(ref[0][p]) for p in ("B1", "B2", "B3")}, "F": tuple(F0)})
    sw = kincas.sweep(m, {"r3": r3}, report=["B1.x", "B1.y", "B3.x", "B3.y"])
    assembles = d >= rod - arm
    assert not assembles.all() and np.array_equal(sw.ok, assembles)
    got = np.stack([sw["B3.x"], sw["B3.y"]], 1)
    assert np.abs(got[sw.ok] - B3[sw.ok]).max() <= 1e-9
    resumes = [e for e in sw.events if e["kind"] == "resume"]
    assert len(resumes) == 1 and resumes[0]["branch"] == "same", resumes
