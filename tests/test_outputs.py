"""The files `kincas solve` writes (--csv, --plot, --animate, --plot-quantities), quantity plots
with their marks, the progress bar, and the one-line message when matplotlib is missing."""
from __future__ import annotations

import argparse
import copy
import csv
import importlib.util
import io
import math
import subprocess
import sys

import numpy as np

from kincas.errors import OutputError
import pytest

import closed_forms as cf
from conftest import EXAMPLES, ROOT, run_cli, write_scene

import kincas
from kincas.cli.progress import Progress

MISSING = 'kincas: --plot needs matplotlib: pip install "kincas[plot]"'


def read_csv(path) -> list[list[str]]:
    with open(path, newline="", encoding="utf-8") as f:
        return list(csv.reader(f))


def nongrashof_scene(steps=37) -> dict:
    """Crank 2, coupler 1.9, rocker 3, ground 4: no assembly for part of the crank's turn."""
    scene = copy.deepcopy(cf.load_scene("fourbar_coupler"))
    scene["parameters"].update({"r1": 4, "r2": 2, "r3": 1.9, "r4": 3, "px": 1, "py": 1})
    scene["guess"] = {"B": [3.0, 2.9]}
    scene["inputs"] = [{"angle": "crank", "sweep": {"from": 0, "to": 360, "steps": steps}}]
    scene["output"] = {"report": ["B.x", "rocker.angle", "rocker.omega"]}
    return scene


# --- CSV ---


@pytest.mark.parametrize("name", ["fairbairn", "slider_crank", "actuator_bellcrank"])
def test_csv_has_a_row_per_pose_the_json_numbers_and_units_in_the_header(capsys, tmp_path, name):
    out = tmp_path / "out.csv"
    code, doc, err = run_cli(capsys, "solve", EXAMPLES / f"{name}.toml", "--json", "--csv", out)
    assert code == 0 and err == ""
    rows = read_csv(out)
    head, body = rows[0], rows[1:]
    names = [*doc["inputs"], *doc["values"]]
    assert [h.split(" [")[0] for h in head] == names + ["status", "flag"]  # inputs first
    assert len(body) == len(doc["status"])
    for j, n in enumerate(names):
        col = doc["inputs"].get(n, doc["values"].get(n))
        # every digit: the text reads back as the very float the JSON holds
        assert [float(r[j]) for r in body] == col
    assert [r[-2] for r in body] == doc["status"]


def test_csv_header_units_follow_the_scene_format():
    from kincas.cli.outputs import write_csv
    from kincas.cli.scene import load
    sc = load(EXAMPLES / "fairbairn.toml")  # mm, deg, s
    buf = io.StringIO()
    write_csv(buf, sc.run(), sc)
    assert buf.getvalue().splitlines()[0] == ("crank.angle [deg],F.y [mm],F.vy [mm/s],lever.angle [deg],"
                                             "lever.omega [deg/s],slot.s [mm],status,flag")


def test_csv_values_match_the_closed_form(capsys, tmp_path):
    out = tmp_path / "s.csv"
    assert run_cli(capsys, "solve", EXAMPLES / "slider_crank.toml", "--csv", out)[0] == 0
    rows = read_csv(out)
    col = {h.split(" [")[0]: [float(r[k]) for r in rows[1:]] for k, h in enumerate(rows[0][:-2])}
    sol = cf.solve("slider_crank", cf.load_scene("slider_crank"))
    np.testing.assert_allclose(col["crank.angle"], cf.input_values(cf.load_scene("slider_crank")))
    np.testing.assert_allclose(col["slider.s"], sol.slide_s("slider"), atol=1e-9, rtol=0)
    np.testing.assert_allclose(col["A.y"], sol.points["A"][:, 1], atol=1e-9, rtol=0)


def test_csv_leaves_unsolved_poses_empty(capsys, tmp_path):
    out = tmp_path / "n.csv"
    code, doc, _ = run_cli(capsys, "solve", write_scene(tmp_path, nongrashof_scene()), "--json", "--csv", out)
    assert code == 3
    body = read_csv(out)[1:]
    # closed form: the four-bar assembles where |B - D| lies between 3 - 1.9 and 3 + 1.9
    th = np.radians(np.linspace(0, 360, 37))
    d = np.hypot(2 * np.cos(th) - 4, 2 * np.sin(th))
    can = (d >= 3 - 1.9) & (d <= 3 + 1.9)
    assert can.any() and not can.all()
    for row, ok, status in zip(body, can, doc["status"]):
        assert row[0] != ""  # the input is always known
        assert (row[1] != "") == ok and (row[3] != "") == ok
        assert row[-2] == status == ("ok" if ok else "no assembly")


def test_unwritable_file_is_one_line_and_status_2(capsys, tmp_path):
    code, _, err = run_cli(capsys, "solve", EXAMPLES / "slider_crank.toml", "--csv",
                           tmp_path / "no" / "such" / "dir.csv")
    assert code == 2
    assert err.count("\n") == 1 and err.startswith("kincas: cannot write ")
    if importlib.util.find_spec("matplotlib"):  # a picture in a format nothing writes
        code, _, err = run_cli(capsys, "solve", EXAMPLES / "slider_crank.toml", "--plot", tmp_path / "x.xyz")
        assert code == 2 and err.count("\n") == 1 and "'xyz' is not supported" in err


# --- pictures from the command line ---


def test_plot_animate_and_quantities_from_the_command_line(capsys, tmp_path):
    pytest.importorskip("matplotlib")
    from PIL import Image
    scene = copy.deepcopy(cf.load_scene("sixbar"))
    scene["inputs"][0]["sweep"]["steps"] = 10
    files = {k: tmp_path / f"out.{e}" for k, e in (("plot", "png"), ("animate", "gif"), ("q", "q.png"))}
    code, _, err = run_cli(capsys, "solve", write_scene(tmp_path, scene), "--plot", files["plot"],
                           "--animate", files["animate"], "--plot-quantities", files["q"])
    assert code == 0 and err == ""
    for key, f in files.items():
        with Image.open(f) as im:
            assert im.size[0] >= 300 and im.size[1] >= 200
            assert (np.asarray(im.convert("L")) < 200).mean() > 0.01, f"{key} is blank"
            if key == "animate":
                assert im.n_frames == 10


def test_missing_matplotlib_is_one_line_and_status_2(capsys, tmp_path, monkeypatch):
    monkeypatch.setitem(sys.modules, "matplotlib", None)  # `import matplotlib` fails
    png, table = tmp_path / "x.png", tmp_path / "x.csv"
    code, _, err = run_cli(capsys, "solve", EXAMPLES / "slider_crank.toml", "--plot", png, "--csv", table)
    assert code == 2
    assert err == MISSING + "\n"
    assert not png.exists() and not table.exists()  # checked before anything is written
    code, _, err = run_cli(capsys, "solve", EXAMPLES / "slider_crank.toml", "--csv", table)
    assert code == 0 and err == "" and len(read_csv(table)) == 74  # CSV needs no matplotlib


def test_the_library_imports_and_writes_csv_without_matplotlib():
    code = ("import sys; sys.modules['matplotlib'] = None\n"
            "import io, kincas, kincas.views.plot, kincas.cli.outputs, kincas.cli.progress\n"
            "m = kincas.Mechanism(ground={'O': (0, 0)}, links=[kincas.Link.bar('c', 'O', 'A', 1),"
            " kincas.Link.bar('r', 'A', 'B', 3)], slides=[kincas.Slide('B', 'ground')],"
            " inputs=[kincas.Input.angle('c')], guess={'B': (4, 0)})\n"
            "b = io.StringIO(); kincas.cli.outputs.write_csv(b, kincas.sweep(m, {'c.angle': [0.0]}))\n"
            "print(b.getvalue().splitlines()[1])\n"
            "try:\n    kincas.plot.draw(m, None)\nexcept ModuleNotFoundError as e:\n    print(e)\n")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, timeout=60)
    assert r.returncode == 0, r.stderr
    lines = r.stdout.splitlines()
    assert lines[0].startswith("0.0,1.0,0.0,4.0,0.0,")  # A at (1, 0), B at (4, 0)
    assert lines[1] == 'kincas.plot.draw needs matplotlib: pip install "kincas[plot]"'


def test_paths_and_pose_options(tmp_path, capsys):
    pytest.importorskip("matplotlib")
    from kincas.cli.outputs import write_outputs
    from kincas.cli.scene import load
    sc = load(EXAMPLES / "fourbar_coupler.toml")
    sw = sc.run()
    args = argparse.Namespace(csv=None, plot=str(tmp_path / "p.png"), animate=None,
                              plot_quantities=None, paths="P, B", pose=-1)
    write_outputs(sc, sw, args)
    assert (tmp_path / "p.png").stat().st_size > 1000
    for bad, text in ((dict(paths="P,Z"), "--paths: unknown point(s) Z"), (dict(pose=73), "--pose: 73")):
        with pytest.raises(OutputError) as e:
            write_outputs(sc, sw, argparse.Namespace(**{**vars(args), **bad}))
        assert str(e.value).startswith(text)


# --- quantities against the input ---


def test_quantity_plot_marks_flags_and_shades_unsolved_poses(tmp_path):
    pytest.importorskip("matplotlib")
    from matplotlib.figure import Figure
    from kincas.cli.outputs import FLAG_STYLE, plot_quantities
    from kincas.cli.scene import load
    sc = load(write_scene(tmp_path, nongrashof_scene()))
    sw = sc.run()
    ok = sw.ok
    first_bad = int(np.flatnonzero(~ok)[0])
    sw.flags = [None] * len(sw)  # these marks only, whatever the solver flagged
    sw.flags[first_bad - 1] = "limit"  # the last pose before the gap
    sw.flags[3] = "singular"
    fig = plot_quantities(sw, scene=sc, fig=Figure())
    x = sw.inputs["crank.angle"] * 180 / math.pi  # the scene's unit
    axes = [a for a in fig.axes if a.get_visible()]
    assert [a.get_ylabel() for a in axes] == ["B.x [mm]", "rocker.angle [deg]", "rocker.omega [deg/s]"]
    for ax in axes:
        for i, kind in ((first_bad - 1, "limit"), (3, "singular")):
            marks = [ln for ln in ax.lines if len(ln.get_xdata()) == 2
                     and np.allclose(ln.get_xdata(), x[i]) and ln.get_color() == FLAG_STYLE[kind][0]]
            assert marks, f"{kind} not marked at {x[i]} on {ax.get_ylabel()}"
        spans = [p.get_patch_transform().transform(p.get_path().vertices)[:, 0] for p in ax.patches]
        assert len(spans) == 1  # one run of unsolved poses
        lo, hi = spans[0].min(), spans[0].max()
        assert (lo < x[~ok]).all() and (x[~ok] < hi).all(), "the gap is shaded"
        assert not ((lo < x[ok]) & (x[ok] < hi)).any(), "no solved pose is"
    legend = [t.get_text() for lg in fig.legends for t in lg.get_texts()]
    assert sorted(legend) == sorted(["not solved", "limit of motion", "singular position"])
    fig.savefig(tmp_path / "q.png")  # it renders


def test_quantity_plot_without_a_scene_names_radians():
    pytest.importorskip("matplotlib")
    from matplotlib.figure import Figure
    from kincas.cli.outputs import plot_quantities
    m = kincas.Mechanism(ground={"A": (0, 0), "D": (4, 0)},
                         links=[kincas.Link.bar("crank", "A", "B", 1), kincas.Link.bar("coupler", "B", "C", 3.5),
                                kincas.Link.bar("rocker", "D", "C", 3)],
                         inputs=[kincas.Input.angle("crank")], guess={"C": (3.6, 2.9)})
    sw = kincas.sweep(m, {"crank.angle": np.linspace(0, 6, 20)}, report=["rocker.alpha"])
    ax = plot_quantities(sw, fig=Figure()).axes[0]
    assert ax.get_ylabel() == "rocker.alpha [rad/s^2]" and ax.get_xlabel() == "crank.angle [rad]"
    np.testing.assert_array_equal(ax.lines[0].get_ydata(), sw["rocker.alpha"])


# --- progress ---


class Clock:
    def __init__(self):
        self.t = 0.0

    def __call__(self):
        return self.t


def test_progress_is_silent_on_short_runs_then_draws_throttled_and_erases_itself():
    out, clock = io.StringIO(), Clock()
    p = Progress(stream=out, clock=clock, delay=0.5, every=0.1, width=10)
    p(0, 1000)
    clock.t = 0.4
    p(256, 1000)
    assert out.getvalue() == ""  # shorter than the delay
    clock.t = 1.0
    p(500, 1000)
    # half done in 1 s: 1 s to go
    assert out.getvalue() == "\rsolving [#####.....]  50%  500/1000  eta 1 s"
    clock.t = 1.05
    p(600, 1000)
    assert out.getvalue().count("\r") == 1  # redrawn at most every 0.1 s
    p(1000, 1000)
    text = out.getvalue()
    assert text.endswith("\r" + " " * len("solving [#####.....]  50%  500/1000  eta 1 s") + "\r")


def test_progress_restarts_for_each_run_and_survives_a_closed_stream():
    out, clock = io.StringIO(), Clock()
    p = Progress(stream=out, clock=clock, delay=0.0, every=0.0, width=4)
    p(0, 10)
    clock.t = 100.0
    p(5, 10)
    p(0, 20)  # a new run (an optimiser's next sweep): the clock starts again
    clock.t = 101.0
    p(10, 20)
    assert out.getvalue().endswith("\rsolving [##..]  50%  10/20  eta 1 s")
    out.close()
    p(15, 20)  # nothing to write to: no exception


def test_a_sweep_reports_progress_and_the_command_line_is_silent_when_piped(capsys):
    out = io.StringIO()
    m = kincas.Mechanism(ground={"A": (0, 0), "D": (4, 0)},
                         links=[kincas.Link.bar("crank", "A", "B", 1), kincas.Link.bar("coupler", "B", "C", 3.5),
                                kincas.Link.bar("rocker", "D", "C", 3)],
                         inputs=[kincas.Input.angle("crank")], guess={"C": (3.6, 2.9)})
    kincas.sweep(m, {"crank.angle": np.linspace(0, 6, 300)}, progress=Progress(stream=out, delay=0, every=0))
    text = out.getvalue()
    assert "0/300" in text and "256/300" in text and text.endswith("\r")
    code, _, err = run_cli(capsys, "solve", EXAMPLES / "fairbairn.toml")  # stderr is not a terminal
    assert code == 0 and err == ""
