"""Studies on a Dask cluster: the same numbers as on local threads, and nothing lost or
repeated when a worker dies mid-study (a LocalCluster on the loopback interface)."""
from __future__ import annotations

import os
import signal

import numpy as np
import pytest

import kincas
from kincas import Input, Link, Mechanism

distributed = pytest.importorskip("distributed")

TH = np.linspace(0, 2 * np.pi, 91)
REPORT = ["max(rocker.angle) - min(rocker.angle)", "mean(C.y) + a4"]


def fourbar():
    return Mechanism(parameters={"a2": 25.0, "a3": 62.25, "a4": 90.0, "a5": 70.0},
                     ground={"A": (0, 0), "D": ("a5", 0)},
                     links=[Link.bar("crank", "A", "B", "a2"), Link.bar("coupler", "B", "C", "a3"),
                            Link.bar("rocker", "D", "C", "a4")],
                     inputs=[Input.angle("crank")], guess={"C": (0.56, 57.25)})


def _same(a, b):
    assert a.status == b.status
    assert np.array_equal(a.params, b.params)
    for t in REPORT:
        assert np.array_equal(np.isnan(a.values[t]), np.isnan(b.values[t]))
        assert np.allclose(a.values[t], b.values[t], rtol=0, atol=1e-12, equal_nan=True)


def test_dask_cluster_gives_the_local_numbers():
    m = fourbar()
    vary = {"a4": (84, 100), "a5": (60, 70)}
    local = kincas.study(m, vary, {"crank.angle": TH}, REPORT, grid=(6, 4), workers=2)
    assert (~local.ok).sum() >= 1 and local.ok.sum() >= 20  # both kinds of rows compared
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=False,
                                  dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        remote = kincas.study(m, vary, {"crank.angle": TH}, REPORT, grid=(6, 4), client=client,
                              chunk=5)
    _same(local, remote)


def test_a_worker_killed_mid_study_loses_nothing():
    m = fourbar()
    vary = {"a4": (84, 100), "a5": (60, 70)}
    inputs = {"crank.angle": np.linspace(0, 2 * np.pi, 721)}
    local = kincas.study(m, vary, inputs, REPORT, designs=60, seed=4, workers=1)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  host="127.0.0.1", dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        pids = client.run(os.getpid)  # worker address -> process id
        victim = sorted(pids.values())[0]
        seen = []

        def progress(done, total):
            seen.append(done)
            if done == 2:  # two chunks back, the rest under way or queued: kill a worker
                os.kill(victim, signal.SIGKILL)
        remote = kincas.study(m, vary, inputs, REPORT, designs=60, seed=4, client=client,
                              chunk=2, progress=progress)
        assert victim not in client.run(os.getpid).values()  # it did die (and was replaced)
    assert seen[-1] == 30 and len(remote.status) == 60
    # every design exactly once, in order, with the numbers the local run gives
    assert len({tuple(r) for r in remote.params}) == 60
    _same(local, remote)


def test_cli_scheduler_writes_the_local_rows(tmp_path, capsys):
    from conftest import EXAMPLES, run_cli

    text = (EXAMPLES / "study_fourbar.toml").read_text()
    text = text.replace("steps = 360", "steps = 37").replace("grid = [41, 41]", "grid = [5, 4]")
    scene = tmp_path / "s.toml"
    scene.write_text(text)
    code, _, err = run_cli(capsys, "study", scene, "--out", tmp_path / "local.csv")
    assert code == 3, err  # designs with a4 - a5 > 37.25 do not assemble
    with distributed.LocalCluster(n_workers=1, threads_per_worker=2, processes=False,
                                  dashboard_address=None) as cluster:
        code, _, err = run_cli(capsys, "study", scene, "--out", tmp_path / "dask.csv",
                               "--scheduler", cluster.scheduler_address)
    assert code == 3, err
    assert (tmp_path / "dask.csv").read_text() == (tmp_path / "local.csv").read_text()


def test_multistart_on_a_cluster_gives_the_local_optima():
    from kincas.synthesis.multistart import multistart

    m = Mechanism(parameters={"d": 4.0}, ground={"A": (0, 0), "D": ("d", 0)},
                  links=[Link.bar("crank", "A", "B", 1), Link.bar("coupler", "B", "C", 3.5),
                         Link.bar("rocker", "D", "C", 3)],
                  inputs=[Input.angle("crank")], guess={"C": (3.6, 2.9)})
    args = (m, {"crank.angle": np.array([0.5])}, {"d": (2.0, 6.0)}, "sum((C.y - 2.9)^2)")
    local = multistart(*args, starts=4, seed=1)
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=False,
                                  dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        remote = multistart(*args, starts=4, seed=1, client=client)
    assert [o.varied for o in remote.optima] == [o.varied for o in local.optima]
    assert len(local.optima) == 2
