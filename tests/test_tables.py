"""Printed tables and files as a reader sees them (issue [12]): no rounding noise shown as
numbers, each column once, units named, the input rate the velocities follow shown,
optimised parameters with units and a mark at a bound, fitted angles within one turn."""
from __future__ import annotations

import csv
import io
import math
import re

import numpy as np
import pytest

from conftest import EXAMPLES, run_cli, write_scene

SLIDER = (EXAMPLES / "slider_crank.toml").read_text(encoding="utf-8")
NOISE = re.compile(r"(?<![\w.])-?\d(\.\d+)?e-(1\d|[2-9]\d)\b|(?<![\w.])-0(?![\w.])")


def _rows(text):
    lines = text.splitlines()
    head = next(i for i, ln in enumerate(lines) if "status" in ln)
    return lines[head], [ln.split() for ln in lines[head + 1:] if ln.strip().endswith("ok")]


def test_no_rounding_noise_in_the_table(capsys):
    code, out, err = run_cli(capsys, "solve", EXAMPLES / "slider_crank.toml")
    assert code == 0, err
    assert not NOISE.search(out), NOISE.search(out).group(0)
    head, rows = _rows(out)
    names = [t for t in head.split() if not t.startswith("[")]
    at90 = next(r for r in rows if r[0] == "90")
    # the crank pin A = (r cos 90 deg, r sin 90 deg) = (0, 50): zero to the mechanism's size
    assert at90[names.index("A.x")] == "0" and at90[names.index("A.y")] == "50"


def test_no_rounding_noise_in_csv_and_json(capsys, tmp_path):
    path = tmp_path / "out.csv"
    code, doc, err = run_cli(capsys, "solve", EXAMPLES / "slider_crank.toml", "--json", "--csv", path)
    assert code == 0, err
    rows = list(csv.reader(io.StringIO(path.read_text())))
    head, body = rows[0], rows[1:]
    i90 = [r[0] for r in body].index("90.0")
    assert float(body[i90][head.index("A.x [mm]")]) == 0.0
    assert not any(c.startswith("-0.0") and float(c) == 0 for r in body for c in r[:-2] if c)
    ax = doc["values"]["A.x"][doc["inputs"]["crank.angle"].index(90)]
    assert ax == 0.0 and math.copysign(1, ax) == 1
    # the cleaning stops at noise: the values that are not zero keep every digit
    th = np.radians(np.array(doc["inputs"]["crank.angle"]))
    assert np.allclose(doc["values"]["A.x"], 50 * np.cos(th), rtol=1e-14, atol=1e-9)
    big = np.abs(50 * np.cos(th)) > 1e-6
    assert np.array(doc["values"]["A.x"])[big] == pytest.approx((50 * np.cos(th))[big], rel=1e-14)


def test_an_input_also_reported_is_one_column(capsys, tmp_path):
    text = SLIDER.replace('report = ["slider.s",', 'report = ["crank.angle", "slider.s",')
    path = write_scene(tmp_path, text)
    out_csv = tmp_path / "x.csv"
    code, out, err = run_cli(capsys, "solve", path, "--csv", out_csv)
    assert code == 0, err
    head, _ = _rows(out)
    assert head.split().count("crank.angle") == 1
    header = next(csv.reader(io.StringIO(out_csv.read_text())))
    assert len(header) == len(set(header)) and sum(h.startswith("crank.angle") for h in header) == 1


def test_sensitivity_units_name_the_parameters_unit(capsys, tmp_path):
    text = SLIDER + '\nsensitivity = { of = ["slider.s", "rod.angle"], to = ["r"] }\n'
    code, out, err = run_cli(capsys, "solve", write_scene(tmp_path, text))
    assert code == 0, err
    assert "d(slider.s)/d(r) [mm/mm]" in out and "d(rod.angle)/d(r) [deg/mm]" in out
    assert " per " not in out


def test_the_table_shows_the_input_rate(capsys, tmp_path):
    code, out, err = run_cli(capsys, "solve", EXAMPLES / "slider_crank.toml")
    assert re.search(r"crank\.angle.*rate 1 deg/s", out), out[:400]
    text = SLIDER.replace("sweep = { from = 0, to = 360, steps = 73 }",
                          "sweep = { from = 0, to = 360, steps = 73 }\nrate = 60\nacceleration = 5")
    code, out, err = run_cli(capsys, "solve", write_scene(tmp_path, text))
    assert re.search(r"rate 60 deg/s.*acceleration 5 deg/s\^2", out), out[:400]


def test_optimize_reports_units_bounds_and_wrapped_angles(capsys):
    code, out, err = run_cli(capsys, "optimize", EXAMPLES / "synthesis_curve.toml")
    assert code in (0, 3), err
    line = next(ln for ln in out.splitlines() if ln.split()[:1] == ["r3"])
    assert "mm" in line and "upper bound" in line  # r3 = 200 is its upper bound
    r2 = next(ln for ln in out.splitlines() if ln.split()[:1] == ["r2"])
    assert "bound" not in r2
    lines = out.splitlines()
    start = next(i for i, ln in enumerate(lines) if "(fitted)" in ln)
    fitted = [float(ln.split()[2]) for ln in lines[start + 1:start + 13]]
    assert all(0 <= a < 360 for a in fitted), fitted
    code, doc, err = run_cli(capsys, "optimize", EXAMPLES / "synthesis_curve.toml", "--json")
    u = doc["curve"]["inputs"]["crank.angle"]
    assert all(0 <= a < 360 for a in u)
    assert doc["at_bound"] == {"r3": "upper"}


def test_the_json_names_the_input_rates(capsys, tmp_path):
    text = SLIDER.replace("sweep = { from = 0, to = 360, steps = 73 }",
                          "sweep = { from = 0, to = 360, steps = 73 }\nrate = 60\nacceleration = 5")
    code, doc, err = run_cli(capsys, "solve", write_scene(tmp_path, text), "--json")
    assert code == 0, err
    assert doc["rates"] == {"crank.angle": 60} and doc["accelerations"] == {"crank.angle": 5}
    # and the velocities follow it: the crank's omega is the input rate, in deg/s
    assert doc["values"]["crank.omega"] == pytest.approx([60.0] * 73, rel=1e-12)
