"""Names renamed for consistency, kept one release under their old spelling.

`renamed(module_globals, {"OldName": "NewName"})` returns a module `__getattr__` (PEP 562):
the old name still gives the object, with a DeprecationWarning naming the new one. Nothing is
warned at import: only code that spells the old name hears about it.

>>> import warnings
>>> g = {"Study": int}
>>> getattr_ = renamed(g, {"StudyResult": "Study"}, "kincas.example")
>>> with warnings.catch_warnings(record=True) as w:
...     warnings.simplefilter("always")
...     getattr_("StudyResult") is int, str(w[0].message)
(True, 'kincas.example.StudyResult is deprecated: use kincas.example.Study (the old name goes in the next release)')
"""
from __future__ import annotations

import warnings


def renamed(namespace: dict, old_to_new: dict[str, str], where: str):
    """A module `__getattr__` serving each old name as its new one, with a DeprecationWarning."""

    def __getattr__(name: str):
        if name in old_to_new:
            new = old_to_new[name]
            warnings.warn(f"{where}.{name} is deprecated: use {where}.{new} (the old name goes in "
                          f"the next release)", DeprecationWarning, stacklevel=2)
            return namespace[new]
        raise AttributeError(f"module {where!r} has no attribute {name!r}")

    return __getattr__
