"""Every cache owned by one place with one interface (issue [15]): the module-level caches
and `Model.memo` are `kincas.core.caches.Memo`s, written only by their owners through
`get_or_build`; the memo builds once per key however many threads ask, stays within its bound,
and is re-entrant.
"""
from __future__ import annotations

import ast
import threading
import time

import pytest

from conftest import ROOT

import kincas
import kincas.core.numeric as numeric
from kincas.core import caches
from kincas.core.caches import Memo

PKG = ROOT / "kincas"
# each cache, by its name in the source, and the one module that may write into it
OWNERS = {"_CACHE": "kincas/core/numeric.py", "_DECIDED": "kincas/core/redundant.py",
          "_LIBS": "kincas/core/c_library.py", "_LOCKS": "kincas/core/batch.py",
          "_SEEN": "kincas/analysis/prepared.py", "_memo": "kincas/core/numeric.py", "memo": None}  # Model.memo: a method, never written
WRITERS = {"setdefault", "pop", "popitem", "update", "clear", "get_or_build", "__setitem__"}


def _name(node) -> str | None:
    """The cache a node names: an attribute (`model.memo`, `numeric._CACHE`) or a bare name,
    except `memo`, which bare is any local table (Model.memo is always an attribute)."""
    if isinstance(node, ast.Attribute):
        return node.attr
    return node.id if isinstance(node, ast.Name) and node.id != "memo" else None


def writes(path) -> list[tuple[int, str]]:
    """(line, cache) of every write into a cache named in OWNERS: item assignment or
    deletion, a mutating method called on it, or the name itself rebound off its owner."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    out = []
    for n in ast.walk(tree):
        targets = (n.targets if isinstance(n, (ast.Assign, ast.Delete))
                   else [n.target] if isinstance(n, (ast.AugAssign, ast.AnnAssign)) else [])
        for t in targets:
            base = t.value if isinstance(t, ast.Subscript) else t
            if _name(base) in OWNERS:
                out.append((n.lineno, _name(base)))
        if (isinstance(n, ast.Call) and isinstance(n.func, ast.Attribute) and n.func.attr in WRITERS
                and _name(n.func.value) in OWNERS):
            out.append((n.lineno, _name(n.func.value)))
    return sorted(set(out))


def test_only_the_owner_writes_each_cache():
    bad = [f"{p.relative_to(ROOT)}:{line}: {name}" for p in sorted(PKG.rglob("*.py")) if p.name != "caches.py"
           for line, name in writes(p) if str(p.relative_to(ROOT)) != OWNERS[name]]
    assert not bad, "caches written outside their owner:\n" + "\n".join(bad)


def test_every_module_cache_is_a_memo():
    """The owners keep their caches as Memos (one interface), not as dicts of their own."""
    import kincas.core.batch as batch
    import kincas.core.c_library as c_library
    import kincas.core.redundant as redundant
    import kincas.analysis.prepared as prepared
    for module, name in [(prepared, "_SEEN"), (numeric, "_CACHE"), (redundant, "_DECIDED"), (c_library, "_LIBS"), (batch, "_LOCKS")]:
        assert isinstance(getattr(module, name), Memo), name


def test_the_scan_finds_writes(tmp_path):
    """The scan above can fail: it sees each way of writing into a cache, not a read."""
    f = tmp_path / "m.py"
    f.write_text("model.memo['k'] = 1\nnumeric._CACHE.setdefault(k, v)\ndel _DECIDED[m]\n"
                 "x = _LIBS.get(k)\nmodel._memo.get_or_build(k, f)\nmodel.memo(k, f)\n_LOCKS = {}\n"
                 "memo = {}\nmemo[k] = 1\nrun.memo.setdefault(k, 1)\n")
    assert writes(f) == [(1, "memo"), (2, "_CACHE"), (3, "_DECIDED"), (5, "_memo"), (7, "_LOCKS"), (10, "memo")]


def at_once(n, ask):
    """ask() from n threads released together; their answers."""
    start, got = threading.Barrier(n), []

    def run():
        start.wait()
        got.append(ask())
    threads = [threading.Thread(target=run) for _ in range(n)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    return got


def test_many_threads_one_build():
    """16 threads ask at once for a key whose build is slow: it runs once, all get its value."""
    memo, calls = Memo(), []

    def build():
        calls.append(1)
        time.sleep(0.05)
        return object()
    got = at_once(16, lambda: memo.get_or_build("k", build))
    assert len(calls) == 1 and len(got) == 16 and all(g is got[0] for g in got)
    assert memo._gates == {}  # nothing left behind once built


def test_different_keys_build_side_by_side():
    """Per-key gates: two slow builds of different keys overlap in time (with a shared gate
    they queue)."""
    for gate, overlap in [(None, True), (threading.RLock(), False)]:
        memo, inside, seen = Memo(gate=gate), [], []

        def build(k):
            inside.append(k)
            seen.append(len(inside))
            time.sleep(0.2)
            inside.remove(k)
            return k
        threads = [threading.Thread(target=memo.get_or_build, args=(k, lambda k=k: build(k))) for k in "ab"]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
        assert (max(seen) == 2) == overlap, gate


def test_bounded_first_in_first_out():
    memo = Memo(bound=256)
    for k in range(300):
        memo.get_or_build(k, lambda k=k: -k)
    memo.get_or_build(44, lambda: pytest.fail("kept: no rebuild"))
    assert len(memo) == 256 and 43 not in memo and 299 in memo and memo.get(44) == -44


def test_reentrant_and_a_failed_build_retries():
    memo = Memo(gate=threading.RLock())
    assert memo.get_or_build("outer", lambda: memo.get_or_build("inner", lambda: 1) + 1) == 2
    with pytest.raises(ZeroDivisionError):
        memo.get_or_build("bad", lambda: 1 / 0)
    assert "bad" not in memo and memo.get_or_build("bad", lambda: 3) == 3 and memo._gates == {}


def test_weak_keys_go_with_their_key():
    class Key:
        pass
    memo, k = Memo(weak=True), Key()
    lock = memo.get_or_build(k, threading.RLock)
    assert memo.get_or_build(k, threading.RLock) is lock and len(memo) == 1
    del k
    import gc
    gc.collect()
    assert len(memo) == 0


def fourbar(coupler=3.5):
    return kincas.Mechanism(ground={"A": (0, 0), "D": (4, 0)},
                            links=[kincas.Link.bar("crank", "A", "B", 1), kincas.Link.bar("coupler", "B", "C", coupler),
                                   kincas.Link.bar("rocker", "D", "C", 3)],
                            inputs=[kincas.Input.angle("crank")], guess={"C": (3.6, 2.9)})


def test_model_of_builds_once_from_many_threads(monkeypatch):
    """The model cache by structure: 8 threads asking for a new structure build one Model
    (before, each could build its own and all but the first were thrown away)."""
    monkeypatch.setattr(numeric, "_CACHE", Memo(bound=64))
    built, init = [], numeric.Model.__init__

    def spy(self, *a, **k):
        built.append(1)
        init(self, *a, **k)
    monkeypatch.setattr(numeric.Model, "__init__", spy)
    m = fourbar(3.25)
    got = at_once(8, lambda: numeric.model_of(m))
    assert len(built) == 1 and len(got) == 8 and all(g is got[0] for g in got)


def test_clear_all_forgets_models():
    m = fourbar()
    model = kincas.model_of(m)
    assert kincas.model_of(m) is model
    kept = {memo: dict(memo._d) for memo in caches._NAMED.values()}
    try:
        caches.clear_all()
        assert all(len(memo) == 0 for memo in kept) and len(kept) >= 3
        assert kincas.model_of(m) is not model and len(numeric._CACHE) == 1
    finally:  # the rest of the suite finds its models and libraries again
        for memo, d in kept.items():
            memo._d.update(d)


def test_the_sweeps_tables_are_memos():
    """The mechanisms prepared for sweeps (per model) and each one's first-pose placements
    are Memos too, within their bounds: RECENT + 3 mechanisms of one structure leave RECENT,
    PLACEMENTS + 3 starting inputs leave PLACEMENTS, and the same inputs are placed once."""
    import numpy as np
    from kincas.analysis.prepared import PLACEMENTS, RECENT, prepared
    ms = [kincas.Mechanism(ground={"A": (0, 0), "D": (4, 0)},
                           links=[kincas.Link.bar("crank", "A", "B", 1 + 0.01 * i), kincas.Link.bar("coupler", "B", "C", 3.5),
                                  kincas.Link.bar("rocker", "D", "C", 3)],
                           inputs=[kincas.Input.angle("crank")], guess={"C": (3.6, 2.9)}) for i in range(RECENT + 3)]
    model = kincas.model_of(ms[0])
    for m in ms:
        prepared(model, m)
    table = model.memo("sweep.prepared", Memo)
    assert isinstance(table, Memo) and len(table) == RECENT
    pm = prepared(model, ms[-1])
    assert isinstance(pm._places, Memo)
    first = [pm.placement(model, np.array([0.1 * k]), pm.guess) for k in range(PLACEMENTS + 3)]
    assert len(pm._places) == PLACEMENTS and all(f is not None for f in first)
    assert pm.placement(model, np.array([0.1 * (PLACEMENTS + 2)]), pm.guess) is first[-1]
