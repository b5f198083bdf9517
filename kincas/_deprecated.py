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


def keyword(where: str, old: str, new: str, old_value, new_value, new_default=None):
    """The value of keyword `new`, or of its 0.1 spelling `old` when only that was given (then
    with a DeprecationWarning naming `new`); ModelError when both were.

    Parameters
    ----------
    where : str
        The function, for the messages.
    old, new : str
        The keyword's old and new names.
    old_value, new_value
        What the caller gave (`old_value` None: not given).
    new_default
        The new keyword's default (what it holds when not given).

    Returns
    -------
    object

    Examples
    --------
    >>> import warnings
    >>> with warnings.catch_warnings(record=True) as w:
    ...     warnings.simplefilter("always")
    ...     keyword("analyse", "samples", "draws", 400, 2000, 2000), str(w[0].message)
    (400, 'analyse(samples=...) is deprecated: use analyse(draws=...) (the old keyword goes in the next release)')
    >>> keyword("analyse", "samples", "draws", None, 300, 2000)
    300
    """
    if old_value is None:
        return new_value
    if new_value is not new_default and new_value != new_default:
        from .errors import ModelError
        raise ModelError(f"{new}: given twice (as {new}= and as its old name {old}=)")
    warnings.warn(f"{where}({old}=...) is deprecated: use {where}({new}=...) (the old keyword "
                  f"goes in the next release)", DeprecationWarning, stacklevel=3)
    return old_value


def attribute(cls_name: str, old: str, new: str) -> property:
    """A read-only property `old` giving the attribute `new`, with a DeprecationWarning: a
    result's field renamed (one word per meaning), its 0.1 spelling kept one release.

    >>> import warnings
    >>> class R:
    ...     draws = 30
    ...     samples = attribute("R", "samples", "draws")
    >>> with warnings.catch_warnings(record=True) as w:
    ...     warnings.simplefilter("always")
    ...     R().samples, str(w[0].message)
    (30, 'R.samples is deprecated: use R.draws (the old name goes in the next release)')
    """
    def get(self):
        warnings.warn(f"{cls_name}.{old} is deprecated: use {cls_name}.{new} (the old name goes in "
                      f"the next release)", DeprecationWarning, stacklevel=2)
        return getattr(self, new)
    return property(get, doc=f"Deprecated name of `{new}`.")
