"""The command line is safe to stop and safe with files (issue [14], items 9-12): Ctrl-C stops
every long command within a second (exit 130, no file left under its final name); a full
disk or an interrupt leaves no partial file under the final name (nor a temporary one); an
output file never overwrites the scene; standard output on a full device, an unwritable
--write folder and a sensitivity of a sensitivity are one line and exit 2, never a traceback."""
from __future__ import annotations

import builtins
import errno
import io
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from conftest import EXAMPLES, ROOT, run_cli, write_scene

FAIRBAIRN = (EXAMPLES / "fairbairn.toml").read_text(encoding="utf-8")
SMALL = FAIRBAIRN.replace("steps = 361", "steps = 7")
STUDY = (EXAMPLES / "study_fourbar.toml").read_text(encoding="utf-8")
CAM = """[cam_design]
base_radius = 40
segments = [{ motion = "rise", angle = 180, lift = 10, law = "harmonic" },
            { motion = "return", angle = 180, lift = 10, law = "harmonic" }]
"""


def one_line_exit_2(code, err, *words):
    assert code == 2, err
    assert "Traceback" not in err and "Exception ignored" not in err, err
    lines = [ln for ln in err.strip().splitlines() if ln.strip()]
    assert len(lines) == 1, err
    for w in words:
        assert w.lower() in err.lower(), (w, err)


def only(folder: Path, *names) -> None:
    """Nothing in `folder` but `names`: no output under its final name, no temporary file."""
    assert sorted(p.name for p in folder.iterdir()) == sorted(names)


def kincas(*args, **kw) -> subprocess.Popen:
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    return subprocess.Popen([sys.executable, "-m", "kincas", *map(str, args)], cwd=ROOT, env=env,
                            stdout=kw.pop("stdout", subprocess.PIPE), stderr=subprocess.PIPE,
                            text=True, **kw)


# --- item 9: Ctrl-C stops every long command within a second ---


def interrupt(proc: subprocess.Popen, after: float = 3.5) -> tuple[float, str]:
    """SIGINT after `after` s (imports done, the work under way); (seconds from the signal to the exit, stderr)."""
    time.sleep(after)
    assert proc.poll() is None, proc.communicate()  # still working: the scene is long enough
    proc.send_signal(signal.SIGINT)
    t = time.perf_counter()
    try:
        _, err = proc.communicate(timeout=10)
    except subprocess.TimeoutExpired:
        proc.kill()
        _, err = proc.communicate()
        return float("inf"), err
    return time.perf_counter() - t, err


def assert_interrupted(proc, waited, err):
    assert waited < 1.5, f"exited {waited:.2f} s after Ctrl-C\n{err}"
    assert proc.returncode == 130, err
    assert "interrupted" in err and "Traceback" not in err, err


@pytest.mark.parametrize("after", [0.15, 0.3, 0.5, 0.7, 0.9, 1.2])
def test_ctrl_c_while_kincas_loads_is_one_line(after):
    """Ctrl-C in the first second, while Python still imports numpy and CasADi (before the
    command's own handler exists), once ended in a KeyboardInterrupt traceback: now the
    command's one line and 130 (or, if the signal beat Python's own handler, death by SIGINT;
    or a finished command), never a traceback."""
    proc = kincas("solve", EXAMPLES / "fourbar_coupler.toml")
    time.sleep(after)
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=30)
    assert "Traceback" not in err and "KeyboardInterrupt" not in err, err
    assert proc.returncode in (130, -signal.SIGINT, 0), (proc.returncode, err)
    if proc.returncode == 130:
        assert err.strip() == "kincas: interrupted", err


def test_interrupt_while_loading_exits_only_as_the_command(monkeypatch):
    """In a user's script or a notebook the KeyboardInterrupt goes on (they may handle it)."""
    from kincas import _launch
    monkeypatch.setattr(sys, "argv", ["my_script.py"])
    _launch.interrupted_while_loading()  # returns: the caller re-raises
    monkeypatch.setattr(sys, "argv", ["/usr/bin/kincas", "solve"])
    with pytest.raises(SystemExit) as e:
        _launch.interrupted_while_loading()
    assert e.value.code == 130


def test_ctrl_c_stops_a_long_study_and_leaves_no_file(tmp_path):
    # 250,000 designs x 360 poses: about half a minute of work
    scene = write_scene(tmp_path, STUDY.replace("grid = [41, 41]", "grid = [500, 500]"))
    proc = kincas("study", scene, "--out", tmp_path / "designs.csv", "--no-progress")
    waited, err = interrupt(proc)
    assert_interrupted(proc, waited, err)
    only(tmp_path, "scene.toml")


def test_ctrl_c_stops_a_long_tolerance_analysis(tmp_path):
    text = FAIRBAIRN.replace("samples = 1000", "samples = 70000")  # about 12 s of sampling
    proc = kincas("tolerance", write_scene(tmp_path, text), "--no-progress")
    waited, err = interrupt(proc)
    assert_interrupted(proc, waited, err)


# `python -m kincas` with a hook that says on standard output when each start begins: the
# test interrupts once the starts are under way, however long imports and setup take on a
# loaded machine (a fixed sleep once fell in them: the interrupt hit `import kincas`, before
# the command line could answer it, and gave a traceback and exit -2)
STARTS_HOOK = """
import runpy, sys
import kincas.synthesis.multistart as ms
call, n = ms._Start.__call__, [0]
def announced(self, x):
    n[0] += 1
    print(f"start {n[0]}", flush=True)
    return call(self, x)
ms._Start.__call__ = announced
sys.argv = ["kincas", *sys.argv[1:]]
runpy.run_module("kincas", run_name="__main__", alter_sys=True)
"""


def test_ctrl_c_stops_a_multistart_optimisation(tmp_path):
    # 3,000 starts: about two minutes; most of it inside IPOPT, which must not swallow Ctrl-C
    scene = write_scene(tmp_path, (EXAMPLES / "synthesis_function.toml").read_text(encoding="utf-8"))
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    proc = subprocess.Popen([sys.executable, "-c", STARTS_HOOK, "optimize", str(scene), "--starts", "3000"],
                            cwd=ROOT, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    for line in proc.stdout:  # the first start has run through IPOPT: the loop is under way
        if line.strip() == "start 2":
            break
    else:
        pytest.fail(f"the starts never began: {proc.communicate()}")
    waited, err = interrupt(proc, after=0.2)  # a few starts on (some 40 ms each, mostly in IPOPT)
    assert_interrupted(proc, waited, err)


def test_ipopt_passes_ctrl_c_on():
    """IPOPT (through CasADi) takes SIGINT as a failed solve and goes on; kincas raises it."""
    import threading

    import casadi as ca
    from kincas.core.cancel import interruptible

    n = 2000  # a problem IPOPT works on for many seconds
    x = ca.MX.sym("x", n)
    f = ca.sumsqr(ca.sin(x) * x - 1) + ca.sum1(ca.cos(x * ca.DM(range(n))) ** 2)
    g = ca.vertcat(*[x[i] * x[i + 1] for i in range(0, n - 1, 7)])
    s = ca.nlpsol("s", "ipopt", {"x": x, "f": f, "g": g},
                  {"ipopt.print_level": 0, "print_time": False, "ipopt.sb": "yes",
                   "error_on_fail": False, "ipopt.max_iter": 3000, "ipopt.tol": 1e-30})
    timer = threading.Timer(0.3, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    t = time.perf_counter()
    with pytest.raises(KeyboardInterrupt):
        with interruptible():
            s(x0=1, lbg=0.5, ubg=2)
    timer.join()
    assert time.perf_counter() - t < 1.5


def test_run_chunks_cancels_pending_work_on_ctrl_c():
    """The main thread hears Ctrl-C while the workers run; pending chunks never start and
    running ones stop at their next checkpoint."""
    import threading

    from kincas.analysis.executor import run_chunks
    from kincas.core.cancel import checkpoint

    started = []

    def work(c):
        started.append(c)
        for _ in range(200):  # 2 s, in short steps
            time.sleep(0.01)
            checkpoint()
        return c

    timer = threading.Timer(0.3, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    t = time.perf_counter()
    with pytest.raises(KeyboardInterrupt):
        run_chunks(work, range(20), workers=2)
    timer.join()
    time.sleep(0.1)  # the running chunks see the cancellation
    assert time.perf_counter() - t < 1.0
    assert len(started) == 2


# --- item 10: no partial file under its final name ---


def fill_up(monkeypatch, folder: Path, room: int = 100) -> None:
    """Every open() (builtins.open, io.open: pathlib's) of a file under `folder` for writing
    gives a file with `room` bytes free."""
    full = FullDisk(folder, room)
    monkeypatch.setattr(builtins, "open", full)
    monkeypatch.setattr(io, "open", full)


class FullDisk:
    """open() of files under `folder` for writing gives files that take `room` bytes, then
    fail with ENOSPC, as a full disk does."""

    def __init__(self, folder: Path, room: int = 1000):
        self.folder, self.room, self.real = str(folder), room, builtins.open

    def __call__(self, file, mode="r", *args, **kw):
        f = self.real(file, mode, *args, **kw)
        if any(c in mode for c in "wax+") and str(os.fspath(file)).startswith(self.folder):
            return _Filling(f, self.room)
        return f


class _Filling:
    def __init__(self, f, room):
        self._f, self._room = f, room

    def write(self, data):
        if len(data) > self._room:
            self._f.write(data[:self._room])
            self._room = 0
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        self._room -= len(data)
        return self._f.write(data)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self._f.close()

    def __iter__(self):
        return iter(self._f)

    def __getattr__(self, name):
        return getattr(self._f, name)


@pytest.mark.parametrize("flag,name", [("--csv", "out.csv"), ("--html", "out.html"),
                                        ("--svg", "out.svg"), ("--dxf", "out.dxf"),
                                        ("--plot", "out.png"),
                                        ("--animate", "out.gif")])
def test_a_full_disk_leaves_no_partial_file(capsys, tmp_path, monkeypatch, flag, name):
    scene = write_scene(tmp_path, SMALL)
    out = tmp_path / "out"
    out.mkdir()
    fill_up(monkeypatch, out)
    code, _, err = run_cli(capsys, "solve", scene, flag, out / name, "--no-progress")
    monkeypatch.undo()
    one_line_exit_2(code, err, name)
    only(out)


def test_a_failed_write_keeps_the_previous_file(capsys, tmp_path, monkeypatch):
    scene = write_scene(tmp_path, SMALL)
    old = tmp_path / "out.csv"
    old.write_text("the previous run's table\n")
    fill_up(monkeypatch, tmp_path, room=10)
    code, _, err = run_cli(capsys, "solve", scene, "--csv", old)
    monkeypatch.undo()
    one_line_exit_2(code, err, "out.csv")
    assert old.read_text() == "the previous run's table\n"
    only(tmp_path, "scene.toml", "out.csv")


def test_ctrl_c_while_animating_leaves_no_gif(capsys, tmp_path, monkeypatch):
    from matplotlib.animation import PillowWriter

    grab, frames = PillowWriter.grab_frame, []

    def grab_then_interrupt(self, **kw):
        frames.append(1)
        if len(frames) == 5:
            raise KeyboardInterrupt
        return grab(self, **kw)
    monkeypatch.setattr(PillowWriter, "grab_frame", grab_then_interrupt)
    scene = write_scene(tmp_path, FAIRBAIRN.replace("steps = 361", "steps = 13"))
    code, _, err = run_cli(capsys, "solve", scene, "--animate", tmp_path / "a.gif")
    assert code == 130 and "interrupted" in err, err
    only(tmp_path, "scene.toml")


@pytest.mark.parametrize("name", ["designs.csv", "designs.nc", "designs.parquet", "map.png"])
def test_study_outputs_on_a_full_disk(capsys, tmp_path, monkeypatch, name):
    pytest.importorskip({"designs.nc": "xarray", "designs.parquet": "pyarrow"}.get(name, "csv"))
    scene = write_scene(tmp_path, STUDY.replace("grid = [41, 41]", "grid = [3, 3]"))
    out = tmp_path / "out"
    out.mkdir()
    if name.endswith(".parquet"):  # pyarrow writes through its own files: fail it half-way
        import pyarrow.parquet as pq

        def half(table, where, **kw):
            Path(where).write_bytes(b"PAR1 half a file")
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        monkeypatch.setattr(pq, "write_table", half)
    else:
        fill_up(monkeypatch, out, room=100)
    flag = "--plot" if name.endswith(".png") else "--out"
    code, _, err = run_cli(capsys, "study", scene, flag, out / name, "--no-progress")
    monkeypatch.undo()
    one_line_exit_2(code, err, name)
    only(out)


@pytest.mark.parametrize("flag", ["--out", "--csv"])
def test_cam_outputs_on_a_full_disk(capsys, tmp_path, monkeypatch, flag):
    scene = write_scene(tmp_path, CAM)
    out = tmp_path / "out"
    out.mkdir()
    fill_up(monkeypatch, out, room=100)
    code, _, err = run_cli(capsys, "cam", scene, flag, out / "cam.txt")
    monkeypatch.undo()
    one_line_exit_2(code, err, "cam.txt")
    only(out)


def test_modes_write_on_a_full_disk(capsys, tmp_path, monkeypatch):
    scene = write_scene(tmp_path, SMALL)
    out = tmp_path / "modes"
    out.mkdir()
    fill_up(monkeypatch, out, room=100)
    code, _, err = run_cli(capsys, "modes", scene, "--starts", "16", "--write", out)
    monkeypatch.undo()
    one_line_exit_2(code, err, "--write")
    only(out)


def test_the_atomic_writer_removes_its_file_on_any_failure(tmp_path):
    from kincas.views.atomic import replacing

    target = tmp_path / "t.csv"
    for error in (OSError(errno.ENOSPC, "full"), KeyboardInterrupt(), ValueError("bad")):
        with pytest.raises(type(error)):
            with replacing(target) as tmp:
                assert Path(tmp).parent == tmp_path and Path(tmp).suffix == ".csv"
                Path(tmp).write_text("half")
                raise error
        only(tmp_path)
    with replacing(target) as tmp:
        Path(tmp).write_text("whole")
    assert target.read_text() == "whole"
    only(tmp_path, "t.csv")
    assert (target.stat().st_mode & 0o777) == 0o666 & ~_umask()


def _umask() -> int:
    u = os.umask(0)
    os.umask(u)
    return u


def test_writing_to_a_device_writes_through(tmp_path):
    """/dev/null (or /dev/stdout) is not a file to replace: written as it is."""
    from kincas.views.atomic import replacing

    with replacing("/dev/null") as tmp:
        assert tmp == "/dev/null"
        Path(tmp).write_text("gone")


# --- item 11: an output never overwrites the scene ---


@pytest.mark.parametrize("command,flag", [("solve", "--csv"), ("solve", "--html"),
                                          ("cam", "--out"), ("cam", "--csv"), ("study", "--out")])
def test_an_output_onto_the_scene_is_refused(capsys, tmp_path, monkeypatch, command, flag):
    text = {"cam": CAM, "study": STUDY}.get(command, SMALL)
    scene = write_scene(tmp_path, text, "victim.toml")
    monkeypatch.chdir(tmp_path)
    for spelled in ("victim.toml", "./victim.toml", str(scene)):
        code, _, err = run_cli(capsys, command, scene, flag, spelled)
        one_line_exit_2(code, err, flag, "scene")
        assert scene.read_text(encoding="utf-8") == text
    link = tmp_path / "link.toml"
    link.symlink_to(scene)
    code, _, err = run_cli(capsys, command, scene, flag, link)
    one_line_exit_2(code, err, flag)
    assert scene.read_text(encoding="utf-8") == text


# --- item 12: one line, exit 2, never a traceback ---


@pytest.mark.parametrize("args", [["solve"], ["solve", "--json"], ["range"], ["range", "--json"],
                                  ["modes", "--starts", "8"]],
                         ids=["solve", "solve-json", "range", "range-json", "modes"])
def test_standard_output_on_a_full_device(tmp_path, args):
    scene = write_scene(tmp_path, SMALL)
    with open("/dev/full", "w") as full:
        proc = kincas(args[0], scene, *args[1:], stdout=full)
        _, err = proc.communicate(timeout=60)
    one_line_exit_2(proc.returncode, err, "standard output")


def test_a_reader_that_leaves_early_is_no_error(tmp_path):
    scene = write_scene(tmp_path, FAIRBAIRN.replace("steps = 361", "steps = 20001"))
    proc = kincas("solve", scene)
    proc.stdout.readline()
    proc.stdout.close()  # `| head -1`
    err = proc.stderr.read()
    proc.wait(timeout=60)
    assert err == "" and proc.returncode == 0, err


def test_modes_write_into_a_folder_that_cannot_exist(capsys, tmp_path):
    scene = write_scene(tmp_path, SMALL)
    (tmp_path / "file").write_text("a regular file")
    code, _, err = run_cli(capsys, "modes", scene, "--starts", "8", "--write", tmp_path / "file" / "modes")
    one_line_exit_2(code, err, "--write")


def test_a_sensitivity_of_a_sensitivity_is_refused(capsys, tmp_path):
    entry = "d(d(C.x)/d(a4))/d(a4)"
    text = STUDY.replace('report = ["C.x", "C.y", "rocker.angle"]', f'report = ["C.x", "{entry}"]')
    code, _, err = run_cli(capsys, "solve", write_scene(tmp_path, text))
    assert code == 2 and "Traceback" not in err, err
    assert "[output] report" in err and entry in err and "sensitivity of a sensitivity" in err, err
