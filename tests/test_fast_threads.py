"""The compiled fast path from several threads and several processes at once (issue [8].4).

Threads: four different mechanisms swept together with the default fast method, compiled,
must give exactly what each gives alone, and match closed forms written here. Processes: two
processes compiling the same new kernel into an empty cache compile it once, and neither
loads a half-written library."""
import json
import os
import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest

import kincas
from kincas import Input, Link, Mechanism, Slide

ROOT = Path(__file__).resolve().parents[1]


def fourbar(a, b, c, d, guess):
    return Mechanism(parameters={"a": a, "b": b, "c": c}, ground={"A": (0, 0), "D": (d, 0)},
                     links=[Link.bar("crank", "A", "B", "a"), Link.bar("coupler", "B", "C", "b"),
                            Link.bar("rocker", "D", "C", "c")],
                     inputs=[Input.angle("crank")], guess={"C": guess})


def fourbar_C(th, a, b, c, d):
    """C of a four-bar (crank a at the origin, rocker c at (d, 0)), the branch above BD."""
    Bx, By = a * np.cos(th), a * np.sin(th)
    ex, ey = d - Bx, -By
    r = np.hypot(ex, ey)
    x = (b * b - c * c + r * r) / (2 * r)
    h = np.sqrt(b * b - x * x)
    return Bx + (x * ex - h * ey) / r, By + (x * ey + h * ex) / r


def slider(r, l, e):
    return Mechanism(ground={"O": (0, 0)},
                     links=[Link.bar("crank", "O", "A", r), Link.bar("rod", "A", "B", l)],
                     slides=[Slide("B", "ground", through=(0, e), name="guide")],
                     inputs=[Input.angle("crank")], guess={"B": (r + l, e)})


def slider_B(th, r, l, e):
    return r * np.cos(th) + np.sqrt(l * l - (e - r * np.sin(th)) ** 2), np.full_like(th, e)


# four mechanisms: two four-bars of one structure (one shared model), a third of another
# structure, and an offset slider-crank
CASES = [
    (fourbar(1.0, 3.5, 3.0, 4.0, (3.6, 2.9)), "C", lambda th: fourbar_C(th, 1.0, 3.5, 3.0, 4.0)),
    (fourbar(1.2, 3.2, 2.8, 4.0, (3.4, 2.6)), "C", lambda th: fourbar_C(th, 1.2, 3.2, 2.8, 4.0)),
    (fourbar(0.8, 4.0, 3.5, 4.5, (3.9, 3.3)), "C", lambda th: fourbar_C(th, 0.8, 4.0, 3.5, 4.5)),
    (slider(1.0, 3.2, 0.4), "B", lambda th: slider_B(th, 1.0, 3.2, 0.4)),
]
TH = np.linspace(0.1, 0.1 + 4 * np.pi, 20001)


@pytest.fixture(scope="module", autouse=True)
def cache(tmp_path_factory):
    with pytest.MonkeyPatch.context() as mp:
        path = tmp_path_factory.mktemp("kincas-cache-fast-threads")
        mp.setenv("KINCAS_CACHE", str(path))
        mp.delenv("KINCAS_NO_COMPILE", raising=False)
        yield path


def one(i):
    m, pt, _ = CASES[i]
    sw = kincas.sweep(m, {"crank.angle": TH}, report=[f"{pt}.x", f"{pt}.y"], compile=True)
    return np.stack([sw[f"{pt}.x"], sw[f"{pt}.y"]]), sw


def test_four_threads_four_mechanisms_give_the_one_thread_answers():
    alone = [one(i)[0] for i in range(4)]
    for i, (m, pt, closed) in enumerate(CASES):
        x, y = closed(TH)
        assert np.abs(alone[i] - np.stack([x, y])).max() <= 1e-12 * m.size(), i
    for _ in range(3):  # several rounds: a race shows up as a difference in some round
        got, errors = [None] * 8, []

        def work(j):
            try:
                got[j] = one(j % 4)
            except Exception as e:  # pragma: no cover - reported below
                errors.append(e)
        threads = [threading.Thread(target=work, args=(j,)) for j in range(8)]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
        assert not errors
        for j in range(8):
            vals, sw = got[j]
            assert sw.ok.all() and not sw.events
            np.testing.assert_array_equal(vals, alone[j % 4])


_CHILD = """
import json, os, sys, time
import numpy as np, kincas
from kincas.core.fast import FastSweeper
go = sys.argv[1]
while not os.path.exists(go):  # start together
    time.sleep(0.005)
m = kincas.Mechanism(ground={"A": (0, 0), "D": (4.25, 0)},
    links=[kincas.Link.bar("crank", "A", "B", 1.1), kincas.Link.bar("coupler", "B", "C", 3.45),
           kincas.Link.bar("rocker", "D", "C", 3.05)], inputs=[kincas.Input.angle("crank")])
model, U = kincas.model_of(m), np.linspace(0, 2 * np.pi, 721)[:, None]
q0 = model.newton(model.initial_q(U[0], [], {"C": (3.6, 2.9)}, 5), U[0], [], 5).q
fs = FastSweeper(model, ["C.x", "C.y"], compile=True)
run = fs.run(U, [], m.size(), q0, U[0], start=1)
print(json.dumps({"compiled": fs.backend.library.times["compile"] > 0, "lib": fs.backend.lib is not None,
                  "x": run.values[0, 1:].tolist(), "y": run.values[1, 1:].tolist()}))
"""


def test_two_processes_compile_a_new_kernel_once(tmp_path):
    cache, go = tmp_path / "cache", tmp_path / "go"
    env = {**os.environ, "KINCAS_CACHE": str(cache), "PYTHONPATH": str(ROOT)}
    env.pop("KINCAS_NO_COMPILE", None)
    procs = [subprocess.Popen([sys.executable, "-c", _CHILD, str(go)], stdout=subprocess.PIPE,
                              stderr=subprocess.PIPE, text=True, env=env) for _ in range(2)]
    time.sleep(0.5)  # both have imported kincas (or nearly): release them together
    go.touch()
    outs = [p.communicate(timeout=600) for p in procs]
    assert all(p.returncode == 0 for p in procs), [o[1][-2000:] for o in outs]
    res = [json.loads(o[0]) for o in outs]
    assert all(r["lib"] for r in res)
    assert sorted(r["compiled"] for r in res) == [False, True]  # one compiled, one waited
    assert len(list(cache.glob("kincas_sweep-*.so"))) == 1 and not list(cache.glob("tmp*"))
    th = np.linspace(0, 2 * np.pi, 721)[1:]
    x, y = fourbar_C(th, 1.1, 3.45, 3.05, 4.25)
    for r in res:
        assert np.abs(np.array(r["x"]) - x).max() <= 1e-12 * 4.25
        assert np.abs(np.array(r["y"]) - y).max() <= 1e-12 * 4.25
