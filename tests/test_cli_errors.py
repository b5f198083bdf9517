"""A wrong scene gives exit status 2 and a message naming the section and the field, never a
traceback (scene format: "Exit status ... 2 when the scene itself is wrong")."""
from __future__ import annotations

import copy
import os
import subprocess
import sys

import pytest

import closed_forms as cf
from conftest import ROOT, run_cli, write_scene


def fourbar() -> dict:
    """A valid crank-rocker four-bar, one pose."""
    scene = copy.deepcopy(cf.load_scene("fourbar_coupler"))
    scene["inputs"] = [{"angle": "crank", "value": 30}]
    return scene


def slider_crank() -> dict:
    scene = copy.deepcopy(cf.load_scene("slider_crank"))
    scene["inputs"] = [{"angle": "crank", "value": 30}]
    return scene


def _set(scene, path, value):
    *head, last = path
    for key in head:
        scene = scene[key]
    scene[last] = value


def _del(scene, path):
    *head, last = path
    for key in head:
        scene = scene[key]
    del scene[last]


def edited(base, *edits):
    """base() with edits: (path, value) sets, (path,) deletes."""
    scene = base()
    for edit in edits:
        if len(edit) == 2:
            _set(scene, *edit)
        else:
            _del(scene, edit[0])
    return scene


# id, the scene (dict, or text written as is), words stderr must contain
CASES = [
    ("not-toml", "this is [not a scene\nlinks = = 3\n", ["TOML"]),
    ("unknown-guess-point", edited(fourbar, (["guess", "Z"], [1, 2])), ["guess", "Z"]),
    ("unknown-input-link", edited(fourbar, (["inputs", 0, "angle"], "nolink")),
     ["inputs", "angle", "nolink"]),
    ("unknown-parameter", edited(fourbar, (["links", "crank", "length"], "a9")),
     ["links", "crank", "length", "a9"]),
    ("two-point-link-without-length", edited(fourbar, (["links", "crank", "length"],)),
     ["links", "crank", "length"]),
    ("infinite-length", edited(fourbar, (["links", "crank", "length"], float("inf"))),
     ["links", "crank", "length"]),
    ("nan-in-ground", edited(fourbar, (["ground", "O4"], [float("nan"), 0])), ["ground", "O4"]),
    ("no-inputs", edited(fourbar, (["inputs"],)), ["inputs", "1", "0"]),
    ("two-inputs-for-one-freedom",
     edited(fourbar, (["inputs"], [{"angle": "crank", "value": 30}, {"angle": "rocker", "value": 100}])),
     ["inputs", "1", "2"]),
    ("slide-along-unknown-body", edited(slider_crank, (["slides", 0, "along"], "nobody")),
     ["slides", "along", "nobody"]),
    ("unknown-quantity-kind", edited(fourbar, (["output", "report"], ["B.x", "B.speed"])),
     ["output", "report", "B.speed"]),
    ("unknown-point-in-report", edited(fourbar, (["output", "report"], ["B.x", "Z.x"])),
     ["output", "report", "Z.x"]),
]


@pytest.mark.parametrize("scene,words", [c[1:] for c in CASES], ids=[c[0] for c in CASES])
@pytest.mark.parametrize("json_flag", [True, False], ids=["json", "text"])
def test_wrong_scene_exits_2_with_a_message(capsys, tmp_path, scene, words, json_flag):
    path = write_scene(tmp_path, scene)
    args = ["solve", path] + (["--json"] if json_flag else [])
    code, _, err = run_cli(capsys, *args)
    assert code == 2, err
    assert "Traceback" not in err
    assert err.strip(), "a message on standard error"
    for word in words:
        assert word in err, f"{word!r} not in the message: {err!r}"


def test_the_bases_are_valid(capsys, tmp_path):
    """The cases above differ from these valid scenes by their one mistake only."""
    for base in (fourbar, slider_crank):
        code, out, err = run_cli(capsys, "solve", write_scene(tmp_path, base()), "--json")
        assert code == 0, err
        assert out["status"] == ["ok"]


def test_missing_file_exits_2(capsys, tmp_path):
    code, _, err = run_cli(capsys, "solve", tmp_path / "nowhere.toml", "--json")
    assert code == 2
    assert "nowhere.toml" in err and "Traceback" not in err


def test_no_traceback_reaches_the_terminal(tmp_path):
    """As a real process: `python -m kincas solve SCENE`."""
    path = write_scene(tmp_path, edited(fourbar, (["links", "crank", "length"], float("inf"))))
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(
        [str(ROOT)] + ([os.environ["PYTHONPATH"]] if os.environ.get("PYTHONPATH") else []))}
    proc = subprocess.run([sys.executable, "-m", "kincas", "solve", str(path)], cwd=tmp_path,
                          env=env, capture_output=True, text=True, timeout=120)
    assert proc.returncode == 2, proc.stderr
    assert "Traceback" not in proc.stderr and "Traceback" not in proc.stdout
    assert "links" in proc.stderr and "crank" in proc.stderr and "length" in proc.stderr
