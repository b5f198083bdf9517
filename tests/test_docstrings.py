"""Every public name of kincas (`kincas.__all__`) and every public method of its public
classes has a numpydoc docstring with an `Examples` section holding a runnable example
(doctests run: pytest has --doctest-modules over kincas/); functions and methods that take
arguments have `Parameters`, functions have `Returns`."""
from __future__ import annotations

import inspect
import re
import types

import kincas


def section(doc: str, name: str) -> str | None:
    """The text of a numpydoc section (a title underlined by dashes), or None."""
    m = re.search(rf"^{name}\n-{{{len(name)}}}\n(.*?)(?=^\w[\w ]*\n-+\n|\Z)", doc, re.M | re.S)
    return m.group(1) if m else None


def problems(qualname: str, obj, method: bool = False) -> list[str]:
    doc = inspect.getdoc(obj.fget if isinstance(obj, property) else obj) or ""
    out = []
    ex = section(doc, "Examples")
    if ex is None or ">>>" not in ex:
        out.append(f"{qualname}: no Examples section with a runnable example")
    if isinstance(obj, property):
        return out
    fn = obj.__func__ if isinstance(obj, (classmethod, staticmethod)) else obj
    try:
        params = [p for p in inspect.signature(fn).parameters.values() if p.name not in ("self", "cls")]
    except (TypeError, ValueError):
        params = []
    if params and section(doc, "Parameters") is None:
        out.append(f"{qualname}: no Parameters section")
    if inspect.isfunction(fn) and not method and section(doc, "Returns") is None:
        out.append(f"{qualname}: no Returns section")
    return out


def public_names():
    for name in kincas.__all__:
        obj = getattr(kincas, name)
        if isinstance(obj, types.ModuleType):  # kincas.optimize: the module is the function too
            obj = getattr(obj, name)
        yield name, obj


def test_every_public_name_has_numpydoc_with_an_example():
    bad = []
    for name, obj in public_names():
        bad += problems(name, obj)
        if inspect.isclass(obj):
            for k, v in vars(obj).items():
                if k.startswith("_"):
                    continue
                if isinstance(v, (property, classmethod, staticmethod)) or inspect.isfunction(v):
                    bad += problems(f"{name}.{k}", v, method=True)
    assert not bad, "\n".join(bad)


def test_the_check_finds_a_missing_example():
    def f(x):
        """Twice x.

        Parameters
        ----------
        x : float

        Returns
        -------
        float
        """
        return 2 * x

    assert problems("f", f) == ["f: no Examples section with a runnable example"]

    def g(x):
        """Twice x.

        Examples
        --------
        >>> g(1)
        2
        """
        return 2 * x

    assert problems("g", g) == ["g: no Parameters section", "g: no Returns section"]
