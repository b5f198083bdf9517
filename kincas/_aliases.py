"""Old module paths as aliases of their new homes.

Scripts written against the first README import `kincas.modes`, `kincas.plot`, ...; those
modules now live in subpackages. A meta-path finder resolves the old names lazily, so
`import kincas` stays cheap and `import kincas.modes` still works, for one more release: it
warns (DeprecationWarning) and names the new path. `kincas.optimize` and `kincas.modes` (the
functions themselves: calling the module calls them) and
`kincas.scene`, `kincas.plot`, `kincas.outputs` (the README's entry points for scenes and
drawings) stay quiet. The presentation modules that left `kincas/cli` for `kincas/views`
(`kincas.cli.plot`, `kincas.cli.svg`, `kincas.notebook`, ...) still import under their old
paths for one release, with a DeprecationWarning naming the new one.
"""
from __future__ import annotations

import importlib
import importlib.abc
import importlib.util
import sys
import warnings

OLD = {
    "symbolic": "core.symbolic", "numeric": "core.numeric", "fast": "core.fast",
    "compiled": "core.compiled", "redundant": "core.redundant",
    "singular": "analysis.singular", "modes": "analysis.modes",
    "sensitivity": "analysis.sensitivity", "tolerance": "analysis.tolerance",
    "optimize": "synthesis.optimize", "simultaneous": "synthesis.simultaneous",
    "expressions": "synthesis.expressions", "curve": "synthesis.curve",
    "checks": "synthesis.checks", "scene": "cli.scene", "outputs": "cli.outputs",
    "plot": "views.plot", "progress": "cli.progress",
}
QUIET = {"optimize", "scene", "plot", "outputs", "modes"}  # current entry points: no warning
# paths of this release's predecessor: warned (DeprecationWarning), removed in the next release
MOVED = {f"cli.{m}": f"views.{m}" for m in ("plot", "svg", "picture", "draw_joints",
                                           "draw_geometry", "dxf", "html", "mapplot", "numbers",
                                           "atomic")}
MOVED["notebook"] = "views.notebook"


class _Loader(importlib.abc.Loader):
    def __init__(self, target: str, old: str | None = None):
        self.target, self.old = target, old

    def create_module(self, spec):
        if self.old is not None:
            warnings.warn(f"{self.old} moved to {self.target}; the old path goes in the next release",
                          DeprecationWarning, stacklevel=2)  # the importer (import frames are skipped)
        module = importlib.import_module(self.target)  # the real module, under both names
        self.spec = module.__spec__
        return module

    def exec_module(self, module):
        module.__spec__ = self.spec  # the import machinery set the alias's: the real one back


class _Finder(importlib.abc.MetaPathFinder):
    def find_spec(self, fullname, path=None, target=None):
        head, _, tail = fullname.partition(".")
        if head != "kincas" or (tail not in OLD and tail not in MOVED):
            return None
        if tail in MOVED:
            return importlib.util.spec_from_loader(fullname, _Loader(f"kincas.{MOVED[tail]}", fullname))
        old = None if tail in QUIET else fullname
        return importlib.util.spec_from_loader(fullname, _Loader(f"kincas.{OLD[tail]}", old))


def install() -> None:
    if not any(isinstance(f, _Finder) for f in sys.meta_path):
        sys.meta_path.insert(0, _Finder())  # only its own old names: before another copy's finder


# functions exported from `kincas`, loaded on first use (`kincas.optimize` is the module of
# 0.1's path and, being callable, the function too: see synthesis/optimize.py)
FUNCTIONS = {"sensitivities": "analysis.sensitivity", "analyse": "analysis.tolerance",
             "find_modes": "analysis.modes", "input_range": "analysis.singular",
             "sweep_designs": "analysis.designs", "study": "synthesis.study",
             "widget": "views.live.widget", "simulate": "analysis.simulate"}


def attribute(name: str):
    """`kincas.modes` and the like as attributes of the package (loaded on first use)."""
    if name in FUNCTIONS:
        return getattr(importlib.import_module(f"kincas.{FUNCTIONS[name]}"), name)
    if name in OLD:
        if name not in QUIET:
            warnings.warn(f"kincas.{name} moved to kincas.{OLD[name]}; the old path goes in the "
                          f"next release", DeprecationWarning, stacklevel=3)  # kincas.__getattr__'s caller
        return importlib.import_module(f"kincas.{OLD[name]}")
    if name in MOVED:
        return importlib.import_module(f"kincas.{name}")  # through the finder: warned
    raise AttributeError(f"module 'kincas' has no attribute {name!r}")
