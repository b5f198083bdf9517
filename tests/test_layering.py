"""The architecture, checked from the source: the import graph of kincas/ (every import
statement of every module, also those inside functions; not those for type annotations only)
has no cycle, the layers depend one way (model <- core <- analysis <- synthesis <- views <-
cli), every module has a place, only the package's face wires the floors together, the
algorithms read no scene, and CasADi (its imports and the symbolic model) stays in
kincas/core. Reading a scene builds no model, and declaring a mechanism runs no solver.
"""
from __future__ import annotations

import ast
import functools
from pathlib import Path

from conftest import ROOT

PKG = ROOT / "kincas"
# the floors, lowest first: each may import its own floor, those below it and the neutral modules
LAYERS = ["kincas.model", "kincas.core", "kincas.analysis", "kincas.synthesis", "kincas.views",
          "kincas.cli"]
# neutral modules, used by every floor: they import nothing but the model and one another
NEUTRAL = {"kincas.errors", "kincas.results", "kincas.result_later", "kincas.units", "kincas.frames", "kincas.result_base",
           "kincas._deprecated", "kincas._launch"}
# the package's face: re-exports the library and registers the notebook displays (so it sits
# above every floor but the command line, which takes the version from it); `python -m kincas`
# runs the command line
FACE = {"kincas": 5, "kincas._aliases": 5, "kincas.__main__": 7}


def module_name(path: Path) -> str:
    parts = list(path.relative_to(ROOT).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def modules() -> dict[str, Path]:
    return {module_name(p): p for p in PKG.rglob("*.py")}


def imports(name: str, path: Path, known: set[str], toplevel: bool = False) -> set[str]:
    """kincas modules (and 'casadi') that `name` imports anywhere in its source (`toplevel`:
    only at import time, not inside functions)."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    out = set()
    for node in _walk(tree, toplevel):
        if isinstance(node, ast.Import):
            targets = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                up = package.split(".")
                up = up[:len(up) - node.level + 1]
                base = ".".join(up + ([base] if base else []))
            # `from pkg import sub` imports the submodule when there is one
            targets = [f"{base}.{a.name}" if f"{base}.{a.name}" in known else base for a in node.names]
        else:
            continue
        for t in targets:
            if t.split(".")[0] == "casadi":
                out.add("casadi")
            while t and t not in known:
                t = t.rpartition(".")[0]
            if t and t.startswith("kincas"):
                out.add(t)
    # importing a module imports its parent packages anyway: not a dependency of the design,
    # except the package's face (`import kincas`, `from .. import x` in a subpackage), which
    # imports the library
    return {t for t in out if t != name and (t == "kincas" or not name.startswith(t + "."))}


def _walk(node, toplevel=False):
    """ast.walk, without the bodies of `if TYPE_CHECKING:` (imports for annotations only),
    and with `toplevel` without function bodies either."""
    for child in ast.iter_child_nodes(node):
        if isinstance(child, ast.If) and "TYPE_CHECKING" in ast.unparse(child.test):
            yield from (n for c in child.orelse for n in [c, *_walk(c, toplevel)])
            continue
        if toplevel and isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda)):
            continue
        yield child
        yield from _walk(child, toplevel)


@functools.lru_cache(maxsize=None)  # read once for all the checks (none changes it)
def graph(toplevel: bool = False) -> dict[str, set[str]]:
    mods = modules()
    return {n: imports(n, p, set(mods), toplevel) for n, p in mods.items()}


def layer(name: str) -> float | None:
    """The module's floor, numbered from 0 (the model); the face between views and the command
    line (5, the command line 6); None for a neutral module."""
    if name in FACE:
        return FACE[name]
    i = next((i for i, L in enumerate(LAYERS) if name == L or name.startswith(L + ".")), None)
    return None if i is None else (i if i < 5 else 6)


def cycles(g: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components of more than one module (Tarjan)."""
    g = {n: {t for t in ts if t in g} for n, ts in g.items()}
    index, low, stack, on, out, counter = {}, {}, [], set(), [], [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in g[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    for v in g:
        if v not in index:
            visit(v)
    return out


def test_every_module_has_a_place():
    """A module outside every floor, the neutral modules and the face would escape the checks."""
    lost = [n for n in modules() if n not in NEUTRAL and layer(n) is None]
    assert not lost, f"modules with no layer: {lost}"


def test_no_import_cycle():
    """No circle of imports anywhere in kincas, lazy imports inside functions included: a lazy
    import that closes a circle hides a dependency the wrong way, it does not remove it."""
    assert cycles(graph()) == []


def test_the_cycle_finder_finds_cycles():
    assert cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]


def test_layers_depend_one_way():
    bad = []
    for n, ts in graph().items():
        ln = layer(n)
        for t in ts:
            if t == "casadi":
                continue
            lt = layer(t)
            if ln is None and not (t in NEUTRAL or lt == 0):
                bad.append(f"{n} (neutral) imports {t}")
            elif ln is not None and lt is not None and lt > ln:
                bad.append(f"{n} imports {t}")
    assert not bad, bad


def test_the_model_imports_no_presentation():
    """Declarations and results do not know how they are drawn: the notebook displays are
    registered from the package's face."""
    views = LAYERS.index("kincas.views")
    bad = [f"{n} imports {t}" for n, ts in graph().items() if layer(n) in (0, None)
           for t in ts if t != "casadi" and (layer(t) or 0) >= views]
    assert not bad, bad


def test_casadi_only_in_core():
    """Symbolic expressions are built only in kincas/core (issue [8].5): every other module
    works on numpy values and calls core functions."""
    bad = {n for n, ts in graph().items() if "casadi" in ts and layer(n) != LAYERS.index("kincas.core")}
    assert not bad, f"casadi imported outside kincas/core: {sorted(bad)}"


def test_the_graph_sees_imports(tmp_path):
    """The checks above can fail: the graph finds known edges, lazy ones included, and an
    `import kincas` inside a function of a subpackage."""
    g = graph()
    assert "casadi" in g["kincas.core.numeric"]
    assert "kincas.core.numeric" in g["kincas.analysis.sweeps"]
    assert "kincas.analysis.modes" in g["kincas.cli.modes"]
    src = tmp_path / "m.py"
    src.write_text("def f():\n    import kincas\n    from . import sweeps\n", encoding="utf-8")
    known = set(modules())
    assert imports("kincas.analysis.x", src, known) == {"kincas", "kincas.analysis.sweeps"}
    assert layer("kincas.views.svg") < layer("kincas.cli.solve") and layer("kincas.results") is None


def test_reading_a_scene_builds_no_model(monkeypatch):
    """Names of points, links and slides are checked from the declarations; only a scene that
    reports quantities of the core's extensions (efforts, cams, ...) builds the model to
    check them."""
    import tomllib

    import kincas.core.numeric as numeric
    from kincas.core.caches import Memo
    from kincas.cli.scene import load
    from kincas.model.names import plain_quantity
    from conftest import EXAMPLES

    built = []
    monkeypatch.setattr(numeric, "_CACHE", Memo(bound=64))  # nothing cached: any model asked for is built
    init = numeric.Model.__init__

    def spy(self, *a, **k):
        built.append(1)
        init(self, *a, **k)
    monkeypatch.setattr(numeric.Model, "__init__", spy)
    plain = 0
    for path in sorted(EXAMPLES.glob("*.toml")):
        before = len(built)
        m = load(path).mechanism
        out = tomllib.loads(path.read_text(encoding="utf-8")).get("output", {})
        sens = out.get("sensitivity", {})
        names = out.get("report", []) + [f"d({q})/d({p})" for q in sens.get("of", []) for p in sens.get("to", [])]
        if all(plain_quantity(m, n) for n in names):
            plain += 1
            assert len(built) == before, f"{path.name}: a model was built while reading it"
    assert plain >= 10


def test_old_paths_import_the_moved_modules_with_a_warning(monkeypatch):
    """The presentation modules left kincas/cli for kincas/views: their old paths give the
    same module for one release, with a DeprecationWarning naming the new path."""
    import importlib
    import sys
    import warnings

    import kincas
    from kincas._aliases import MOVED
    assert set(MOVED) >= {"cli.plot", "cli.svg", "cli.html", "cli.dxf", "notebook"}
    for old, new in MOVED.items():
        monkeypatch.delitem(sys.modules, f"kincas.{old}", raising=False)
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            mod = importlib.import_module(f"kincas.{old}")
        assert mod is importlib.import_module(f"kincas.{new}") and mod.__name__ == f"kincas.{new}"
        assert mod.__spec__.name == f"kincas.{new}"  # the alias does not rename the module
        assert [w.category for w in caught] == [DeprecationWarning], old
        assert f"kincas.{new}" in str(caught[0].message)
    with warnings.catch_warnings():  # the 0.1 layout's paths of the README: no warning
        warnings.simplefilter("error")
        assert kincas.plot.draw is importlib.import_module("kincas.views.plot").draw


def test_the_displays_are_registered_from_the_face():
    """`import kincas` gives Mechanism and Sweep their notebook displays without the model
    importing the views."""
    import kincas
    import kincas.views
    assert kincas.Mechanism._repr_svg_ is kincas.views.mechanism_svg_display
    assert kincas.Sweep._repr_html_ is kincas.views.sweep_html_display


def assigned_from_outside(name: str, path: Path, known: set[str]) -> list[str]:
    """`X.attr = ...` (or setattr(X, ...)) in `name` where X is a kincas module it imported
    or a name it imported from one: an edit of another module's objects."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    foreign = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            foreign |= {(a.asname or a.name).split(".")[0] for a in node.names if a.name.startswith("kincas")}
        elif isinstance(node, ast.ImportFrom) and (node.level or (node.module or "").startswith("kincas")):
            foreign |= {a.asname or a.name for a in node.names}
    out = []
    for node in ast.walk(tree):
        targets = []
        if isinstance(node, (ast.Assign, ast.AugAssign, ast.AnnAssign)):
            targets = node.targets if isinstance(node, ast.Assign) else [node.target]
        elif isinstance(node, ast.Call) and ast.unparse(node.func) == "setattr" and node.args:
            targets = [ast.Attribute(value=node.args[0], attr="?")]
        for t in targets:
            if isinstance(t, ast.Attribute) and isinstance(t.value, ast.Name) and t.value.id in foreign:
                out.append(f"{name}:{t.lineno if hasattr(t, 'lineno') else node.lineno}: {ast.unparse(t)}")
    return out


def test_no_floor_edits_another_modules_objects(tmp_path):
    """The core used to install its rank test into kincas/model by assignment, and the model
    learnt its displays from a lazy import of the views: only the package's face wires the
    floors together (and says so)."""
    mods = modules()
    bad = [hit for n, p in mods.items() if n not in FACE for hit in assigned_from_outside(n, p, set(mods))]
    assert not bad, bad
    src = tmp_path / "m.py"
    src.write_text("from ..model import mechanism as _m\n_m._rank_decision = len\n", encoding="utf-8")
    assert assigned_from_outside("kincas.core.x", src, set(mods)) == ["kincas.core.x:2: _m._rank_decision"]


def test_names_are_taken_from_their_home():
    """A quantity's name is parsed by the model (kincas/model/names.py): printing a number or
    reading a scene does not pass through the symbolic core, which only re-exports them."""
    import kincas.model.names as names
    home = {k for k in vars(names) if not k.startswith("__")}
    bad = []
    for n, p in modules().items():
        if layer(n) == 1:
            continue
        for node in ast.walk(ast.parse(p.read_text(encoding="utf-8"))):
            if isinstance(node, ast.ImportFrom) and (node.module or "").endswith("core.symbolic"):
                bad += [f"{n}: {a.name}" for a in node.names if a.name in home]
    assert not bad, bad


def test_algorithms_read_no_scene():
    """The model, the core, the analyses and the synthesis take mechanisms and plain values:
    none parses TOML or reaches into a scene (`sc.study`, its raw sections); the command line
    reads the sections (cli/tolerance.py, cli/scene_optimize.py, cli/scene_guess.py)."""
    bad = []
    for n, p in modules().items():
        if layer(n) not in (0, 1, 2, 3):
            continue
        for node in ast.walk(ast.parse(p.read_text(encoding="utf-8"))):
            if isinstance(node, (ast.Import, ast.ImportFrom)):
                names = [a.name for a in node.names] + [getattr(node, "module", None) or ""]
                bad += [f"{n}: imports {x}" for x in names if x.split(".")[0] == "tomllib"]
            elif isinstance(node, ast.Attribute) and node.attr in ("study", "raw", "refuse_jerks"):
                bad.append(f"{n}:{node.lineno}: .{node.attr}")
    assert not bad, bad


def test_the_symbolic_model_stays_in_the_core():
    """Outside kincas/core the compiled model is asked for plain values (names of unknowns,
    which are lengths, checks of names, vectorised quantities): nothing reaches its CasADi
    expressions through `model.sym`."""
    bad = []
    for n, p in modules().items():
        if layer(n) == 1:
            continue
        for node in ast.walk(ast.parse(p.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Attribute) and node.attr == "sym":
                bad.append(f"{n}:{node.lineno}: {ast.unparse(node)}")
    assert not bad, bad
