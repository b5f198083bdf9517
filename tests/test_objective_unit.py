"""The unit of `kincas optimize`'s objective (issue [12]: "kincas optimize reports no units").

Each expected unit is worked out by hand from the example's objective: a sum of squared
lengths in mm is mm^2, of squared angles in degrees deg^2, a length alone mm."""
import pytest
from conftest import ROOT, run_cli

from kincas.synthesis.dimensions import expression_unit
from kincas.synthesis.expressions import parse


@pytest.mark.parametrize("example, unit", [
    ("synthesis_path", "mm^2"),       # sum((P.x - tx)^2 + (P.y - ty)^2)
    ("synthesis_function", "deg^2"),  # sum((rocker.angle - psi)^2) in a degree scene
    ("synthesis_slider", "mm"),       # minimize = "l", a length parameter
    ("synthesis_curve", "mm^2"),      # squared distances to the target curve
])
def test_optimize_reports_the_objective_unit(capsys, example, unit):
    scene = ROOT / "examples" / f"{example}.toml"
    code, doc, _ = run_cli(capsys, "optimize", scene, "--json")
    assert code == 0 and doc["objective_unit"] == unit
    code, text, _ = run_cli(capsys, "optimize", scene)
    assert f"objective [{unit}]: " in text


LABELS = {"P.x": "mm", "P.vx": "mm/s", "rocker.angle": "deg", "effort(crank.angle)": "force·mm",
          "crank.omega": "deg/s", "r1": "mm", "C.curvature": "1/mm"}


@pytest.mark.parametrize("text, unit", [
    ("max(abs(effort(crank.angle)))", "force·mm"),
    ("effort(crank.angle) * crank.omega", "force·mm·deg/s"),   # power, in the scene's units
    ("sqrt(sum(P.x^2 + r1^2))", "mm"),
    ("mean(P.vx) / r1", "1/s"),
    ("C.curvature * P.x", ""),                                # a pure number
    ("atan2(P.x, r1)", "deg"),
    ("2 * pi * r1", "mm"),
    ("P.x^-2", "1/mm^2"),
])
def test_units_follow_dimensional_analysis(text, unit):
    labels = {**LABELS, "__angle__": "deg"}
    assert expression_unit(parse(text, "minimize"), labels.get) == unit


@pytest.mark.parametrize("text", [
    "P.x + rocker.angle",      # a length plus an angle: no unit rather than a wrong one
    "P.x ^ r1",                # a power that is not a number
    "sqrt(P.x)",               # the square root of a length
    "hypot(P.x, P.vx)",
])
def test_undecidable_units_are_not_printed(text):
    assert expression_unit(parse(text, "minimize"), LABELS.get) is None
