"""A process that ends while a compile runs in the background ends at once and clean.

The compile of a structure swept again runs on a background thread (kincas/core/compiled.py).
When the process exits, normally or on Ctrl-C, mid-compile: the interpreter is gone within a
second, the compiler is killed (not left orphaned), its temporary folder is removed, and the
cache holds no library, whole or partial. The compiler here is a stand-in ($CC) that records
its process id and then takes a minute: the compile is surely under way when the process ends.
"""
from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap
import time

import pytest

from conftest import ROOT

pytestmark = pytest.mark.skipif(os.name != "posix", reason="process groups and signals")

CHILD = textwrap.dedent("""
    import os, sys, time
    import casadi as ca
    from kincas.core.compiled import Backend, Library
    x = ca.SX.sym("x")
    lib = Library("kincas_exit_test", [ca.Function("twice", [x], [2 * x])], "", {}, {})
    backend = Backend(None, lambda: lib, "test kernel")
    backend.start()                        # the background compile
    pidfile = os.environ["KINCAS_TEST_PIDFILE"]
    while not (os.path.exists(pidfile) and open(pidfile).read().strip()):
        time.sleep(0.01)                   # the compiler runs
    print("compiling", flush=True)
    if sys.argv[1] == "sigint":
        time.sleep(60)                     # Ctrl-C comes from the test
    sys.stdin.readline()                   # the test has seen the compiler running: exit
""")


def alive(pid: int) -> bool:
    try:
        with open(f"/proc/{pid}/stat") as f:
            return f.read().rsplit(")", 1)[1].split()[0] != "Z"   # a zombie has ended
    except OSError:
        return False


@pytest.mark.parametrize("how", ["exit", "sigint"])
def test_exit_mid_compile_kills_the_compiler_and_leaves_nothing(tmp_path, how):
    cache, pidfile = tmp_path / "cache", tmp_path / "cc.pid"
    cc = tmp_path / "slowcc"
    cc.write_text(f'#!/bin/sh\necho $$ > "{pidfile}"\nexec sleep 60\n')
    cc.chmod(0o755)
    env = {**os.environ, "KINCAS_CACHE": str(cache), "CC": str(cc), "KINCAS_TEST_PIDFILE": str(pidfile)}
    env.pop("KINCAS_NO_COMPILE", None)
    proc = subprocess.Popen([sys.executable, "-c", CHILD, how], cwd=ROOT, env=env, text=True,
                            stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    pid = None
    try:
        assert proc.stdout.readline().strip() == "compiling", proc.stderr.read()
        pid = int(pidfile.read_text())
        assert alive(pid)
        t0 = time.monotonic()
        if how == "sigint":
            proc.send_signal(signal.SIGINT)
        else:
            proc.stdin.write("exit\n")
            proc.stdin.flush()
        proc.wait(timeout=30)
        took = time.monotonic() - t0
        err = proc.stderr.read()
        print(f"{how}: exited {took:.3f} s after")
        assert took < 1.0, f"{took:.2f} s to exit; {err[-500:]}"
        assert not alive(pid), "the compiler was left running"
        left = sorted(p.name for p in cache.iterdir() if p.is_dir() or p.suffix == ".so")
        assert left == [], left          # no temporary folder, no library, whole or partial
        assert "could not compile" not in err
    finally:
        if proc.poll() is None:
            proc.kill()
        if pid is not None and alive(pid):
            os.kill(pid, signal.SIGKILL)
