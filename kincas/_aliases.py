"""Old module paths (kincas 0.1's flat layout) as aliases of their new homes.

Scripts written against the first README import `kincas.modes`, `kincas.plot`, ...; those
modules now live in subpackages. A meta-path finder resolves the old names lazily, so
`import kincas` stays cheap and `import kincas.modes` still works.
"""
from __future__ import annotations

import importlib
import importlib.abc
import importlib.util
import sys

OLD = {
    "symbolic": "core.symbolic", "numeric": "core.numeric", "fast": "core.fast",
    "compiled": "core.compiled", "redundant": "core.redundant",
    "singular": "analysis.singular", "modes": "analysis.modes",
    "sensitivity": "analysis.sensitivity", "tolerance": "analysis.tolerance",
    "optimize": "synthesis.optimize", "simultaneous": "synthesis.simultaneous",
    "expressions": "synthesis.expressions", "curve": "synthesis.curve",
    "checks": "synthesis.checks", "scene": "cli.scene", "outputs": "cli.outputs",
    "plot": "cli.plot", "progress": "cli.progress",
}


class _Loader(importlib.abc.Loader):
    def __init__(self, target: str):
        self.target = target

    def create_module(self, spec):
        return importlib.import_module(self.target)  # the real module, under both names

    def exec_module(self, module):
        pass  # already executed under its new name


class _Finder(importlib.abc.MetaPathFinder):
    def find_spec(self, fullname, path=None, target=None):
        head, _, tail = fullname.partition(".")
        if head != "kincas" or tail not in OLD:
            return None
        return importlib.util.spec_from_loader(fullname, _Loader(f"kincas.{OLD[tail]}"))


def install() -> None:
    if not any(isinstance(f, _Finder) for f in sys.meta_path):
        sys.meta_path.append(_Finder())


# functions exported from `kincas`, loaded on first use (`kincas.optimize` is the module of
# 0.1's path and, being callable, the function too: see synthesis/optimize.py)
FUNCTIONS = {"sensitivities": "analysis.sensitivity", "analyse": "analysis.tolerance",
             "find_modes": "analysis.modes", "input_range": "analysis.singular",
             "sweep_designs": "analysis.designs", "study": "synthesis.study"}


def attribute(name: str):
    """`kincas.modes` and the like as attributes of the package (loaded on first use)."""
    if name in FUNCTIONS:
        return getattr(importlib.import_module(f"kincas.{FUNCTIONS[name]}"), name)
    if name in OLD:
        return importlib.import_module(f"kincas.{OLD[name]}")
    raise AttributeError(f"module 'kincas' has no attribute {name!r}")
