"""compile=None: repeated short sweeps get the compiled kernel (issues [8], [15]).

A one-off short sweep runs in the virtual machine and compiles nothing; a structure swept
again (its sweeps adding up to BACKGROUND_MIN_POSES), or whose sweeps add up to
BACKGROUND_POSES, compiles its kernel in a background thread while the virtual machine keeps
serving, and once it is loaded the sweeps run compiled. Every sweep, before, during and
after, gives the circle-intersection answer written here. compile=False never compiles;
$KINCAS_NO_COMPILE is obeyed.
"""
import threading

import numpy as np
import pytest

import kincas
from kincas import Input, Link, Mechanism
from kincas.core.fast import sweeper_for

REPORT = ("C.x", "C.y")


@pytest.fixture()
def cache(tmp_path, monkeypatch):
    monkeypatch.setenv("KINCAS_CACHE", str(tmp_path))
    monkeypatch.delenv("KINCAS_NO_COMPILE", raising=False)
    return tmp_path


def fourbar(b, name):  # a parameter name of its own per test: a structure no other test has
    return Mechanism(parameters={name: b}, ground={"A": (0, 0), "D": (4, 0)},
                     links=[Link.bar("crank", "A", "B", 1.0), Link.bar("coupler", "B", "C", name),
                            Link.bar("rocker", "D", "C", 3.0)],
                     inputs=[Input.angle("crank")], guess={"C": (3.6, 2.9)})


def closed_C(th, b):
    Bx, By = np.cos(th), np.sin(th)
    ex, ey = 4 - Bx, -By
    r = np.hypot(ex, ey)
    x = (b * b - 9 + r * r) / (2 * r)
    h = np.sqrt(b * b - x * x)
    return Bx + (x * ex - h * ey) / r, By + (x * ey + h * ex) / r


def check(sw, th, b):
    Cx, Cy = closed_C(th, b)
    assert sw.ok.all()
    assert np.abs(sw["C.x"] - Cx).max() < 1e-12 and np.abs(sw["C.y"] - Cy).max() < 1e-12


@pytest.fixture()
def poses(monkeypatch):  # compile after 1,000 poses (20,000 by default): quick tests
    monkeypatch.setattr(kincas.core.fast, "BACKGROUND_POSES", 1000)


def test_a_structure_swept_again_compiles_in_the_background(cache):
    m, th = fourbar(3.5, "policy_b1"), np.linspace(0, 2 * np.pi, 360)
    fast = sweeper_for(kincas.model_of(m), REPORT, None)
    sw = kincas.sweep(m, {"crank.angle": th}, report=list(REPORT))  # a one-off sweep: nothing compiled
    check(sw, th, 3.5)
    assert sw.info["fast pass"] == "virtual machine"
    assert fast.backend.lib is None and fast.backend._thread is None
    assert not list(cache.glob("*.so"))
    check(kincas.sweep(m, {"crank.angle": th}, report=list(REPORT)), th, 3.5)  # again: starts it
    assert fast.backend._thread is not None
    fast.backend._thread.join(timeout=120)
    assert fast.backend.lib is not None and list(cache.glob("kincas_sweep-*.so"))
    assert not [p for p in cache.iterdir() if p.is_dir()]  # no half-written build left
    sw = kincas.sweep(m, {"crank.angle": th}, report=list(REPORT))  # compiled now
    check(sw, th, 3.5)
    assert sw.info["fast pass"] == "compiled"


def test_short_sweeps_compile_once_they_add_up(cache, poses):
    # swept again, but briefly (fewer than BACKGROUND_MIN_POSES poses in all): nothing, until
    # the sweeps add up to BACKGROUND_POSES (1,000 here)
    m, th = fourbar(3.52, "policy_b0"), np.linspace(0, 1, 120)
    fast = sweeper_for(kincas.model_of(m), REPORT, None)
    for _ in range(4):  # 480 poses
        check(kincas.sweep(m, {"crank.angle": th}, report=list(REPORT)), th, 3.52)
    assert fast.backend._thread is None and not list(cache.glob("*.so"))
    check(kincas.sweep(m, {"crank.angle": np.linspace(0, 1, 600)}, report=list(REPORT)),
          np.linspace(0, 1, 600), 3.52)  # 1,080 poses
    assert fast.backend._thread is not None
    fast.backend._thread.join(timeout=120)
    assert fast.backend.lib is not None


def test_sweeps_from_threads_while_the_kernel_compiles(cache, poses):
    m, th = fourbar(3.45, "policy_b2"), np.linspace(0, 2 * np.pi, 500)
    fast = sweeper_for(kincas.model_of(m), REPORT, None)
    kincas.sweep(m, {"crank.angle": th}, report=list(REPORT))
    errors = []

    def work():
        try:
            for _ in range(6):
                check(kincas.sweep(m, {"crank.angle": th}, report=list(REPORT)), th, 3.45)
        except AssertionError as e:  # pragma: no cover - reported below
            errors.append(e)
    ts = [threading.Thread(target=work) for _ in range(3)]
    for t in ts:
        t.start()
    for t in ts:
        t.join()
    assert not errors
    fast.backend._thread.join(timeout=120)
    check(kincas.sweep(m, {"crank.angle": th}, report=list(REPORT)), th, 3.45)
    assert fast.backend.lib is not None


def test_compile_false_and_no_compile_never_compile(cache, monkeypatch, poses):
    m, th = fourbar(3.4, "policy_b3"), np.linspace(0, 1, 400)
    for _ in range(3):
        check(kincas.sweep(m, {"crank.angle": th}, report=list(REPORT), compile=False), th, 3.4)
    assert sweeper_for(kincas.model_of(m), REPORT, False).backend._thread is None
    monkeypatch.setenv("KINCAS_NO_COMPILE", "1")
    for _ in range(3):
        check(kincas.sweep(m, {"crank.angle": th}, report=list(REPORT)), th, 3.4)
    assert sweeper_for(kincas.model_of(m), REPORT, None).backend._thread is None
    assert not list(cache.glob("*.so"))


# --- one rule: a library built or found is used from then on (issue [15]) ---


@pytest.mark.parametrize("first", [None, False])
def test_a_library_built_by_compile_true_serves_the_default_sweeps_after_it(cache, first):
    # before: the default sweeps' sweeper, made before the library existed, kept running
    # the virtual machine after compile=True had built and loaded it in the same process
    m, th = fourbar(3.4, f"policy_rule_{first}"), np.linspace(0, 2 * np.pi, 360)
    sw = kincas.sweep(m, {"crank.angle": th}, report=list(REPORT), compile=first)
    check(sw, th, 3.4)
    assert sw.info["fast pass"] == "virtual machine"  # a short sweep compiles nothing
    sw = kincas.sweep(m, {"crank.angle": th}, report=list(REPORT), compile=True)
    check(sw, th, 3.4)
    assert sw.info["fast pass"] == "compiled"
    for _ in range(2):
        sw = kincas.sweep(m, {"crank.angle": th}, report=list(REPORT))
        check(sw, th, 3.4)
        assert sw.info["fast pass"] == "compiled"
    sw = kincas.sweep(m, {"crank.angle": th}, report=list(REPORT), compile=False)  # still obeyed
    check(sw, th, 3.4)
    assert sw.info["fast pass"] == "virtual machine"


def test_the_sweepers_of_one_kernel_share_its_functions(cache):
    model = kincas.model_of(fourbar(3.3, "policy_rule_share"))
    a, b = sweeper_for(model, REPORT, None), sweeper_for(model, REPORT, True)
    assert a is not b and a.functions is b.functions  # one code generation, one library
