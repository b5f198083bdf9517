"""Each algorithm and each threshold once, checked from the source (issue [15], "the same
algorithm several times"): the numerical thresholds of kincas/core and kincas/analysis live in
kincas/core/tolerances.py; the branch test (two modes differ, both defined) and the window of
a located singular position along a step are each written once.
"""
from __future__ import annotations

import ast
import re

from conftest import ROOT

PKG = ROOT / "kincas"
HOME = PKG / "core" / "tolerances.py"
# a float literal this small is a tolerance, whatever its use
SMALL = 1e-2


def sources(*layers):
    for layer in layers:
        yield from sorted((PKG / layer).rglob("*.py"))


def tolerance_literals(path):
    """(line, value) of every float literal 0 < |v| <= SMALL in the code (docstrings and
    comments are strings, not literals), and of every module-level UPPER_CASE name bound
    to a float literal (a threshold by its name, whatever its size)."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    out = [(n.lineno, n.value) for n in ast.walk(tree)
           if isinstance(n, ast.Constant) and type(n.value) is float and 0 < abs(n.value) <= SMALL]
    for n in tree.body:
        if (isinstance(n, ast.Assign) and isinstance(n.value, ast.Constant) and type(n.value.value) is float
                and all(isinstance(t, ast.Name) and t.id.upper() == t.id for t in n.targets)):
            out.append((n.lineno, n.value.value))
    return sorted(set(out))


# Small numbers that are not numerical thresholds: times in seconds, with the reason
NOT_TOLERANCES = {
    ("kincas/core/cancel.py", 0.1): "WAIT, seconds between looks for a cancellation",
    ("kincas/analysis/design_job.py", 1e-6): "a floor of a call's measured time in seconds",
    ("kincas/analysis/certify_msolve.py", 0.005): "seconds before the first look at msolve (then doubled)",
}


def test_every_threshold_in_tolerances():
    bad = [f"{p.relative_to(ROOT)}:{line}: {v!r}" for p in sources("core", "analysis") if p != HOME
           for line, v in tolerance_literals(p) if (str(p.relative_to(ROOT)), v) not in NOT_TOLERANCES]
    assert not bad, "thresholds outside kincas/core/tolerances.py:\n" + "\n".join(bad)


def test_the_scan_finds_thresholds(tmp_path):
    """The scan above can fail: it sees a literal in code, a named constant, not a docstring."""
    f = tmp_path / "m.py"
    f.write_text('"""1e-9 in text."""\nWIDE = 0.5\ndef f(x):\n    return x < 1e-9\n')
    assert tolerance_literals(f) == [(2, 0.5), (4, 1e-9)]


# (a != b) & (a != 0) & (b != 0): the modes changed and both are defined
BRANCH_TEST = re.compile(r"\((\w[\w\[\]:\-+ ]*?) != (\w[\w\[\]:\-+ ]*?)\) & \(\1 != 0\) & \(\2 != 0\)")
WINDOW = re.compile(r"-\s*(1e-9|STEP_SLACK)\s*<=.*<=\s*1\s*\+\s*(1e-9|STEP_SLACK)")


def matching_lines(pattern) -> list[str]:
    """path:line of every line of kincas/core and kincas/analysis that `pattern` matches."""
    return [f"{p.relative_to(ROOT)}:{i}" for p in sources("core", "analysis")
            for i, line in enumerate(p.read_text(encoding="utf-8").splitlines(), 1) if pattern.search(line)]


def test_one_branch_test():
    """Written once, in kincas/core/branch.py (it was written 7 times in continuation, resume, events)."""
    hits = matching_lines(BRANCH_TEST)
    assert len(hits) == 1 and hits[0].startswith("kincas/core/branch.py:"), "the branch test written out instead of core.branch.changed:\n" + "\n".join(hits)
    assert BRANCH_TEST.search("np.any((s0 != s1) & (s0 != 0) & (s1 != 0))")
    assert BRANCH_TEST.search("(signs[:-1] != signs[1:]) & (signs[:-1] != 0) & (signs[1:] != 0)")


def test_one_step_window():
    """Written once, in kincas/core/limits.on_step (it was written 5 times in continuation, events, resume)."""
    hits = matching_lines(WINDOW)
    assert len(hits) == 1 and hits[0].startswith("kincas/core/limits.py:"), "the window of a located position written out instead of core.limits.on_step:\n" + "\n".join(hits)
    assert WINDOW.search("if found is not None and -1e-9 <= found[2] <= 1 + 1e-9:")
    assert WINDOW.search("if found is None or not -STEP_SLACK <= found[2] <= 1 + STEP_SLACK:")


# Modules still over 400 lines (issue [15]: to be split); no other module may pass it.
LONG: set[str] = set()


def test_modules_at_most_400_lines():
    over = {str(p.relative_to(ROOT)): len(p.read_text(encoding="utf-8").splitlines()) for p in PKG.rglob("*.py")}
    over = {k: n for k, n in over.items() if n > 400}
    assert set(over) <= LONG, {k: n for k, n in over.items() if k not in LONG}
