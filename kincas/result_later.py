"""A sweep's status, flags and iteration counts, made when first read (`Sweep._built`).

A warm sweep of 360 poses whose every pose is solved would spend as much building an object
array of 360 "ok" strings (and counting them again in `Sweep.ok`), a list of 360 Nones and an
integer copy of Newton's step counts as a third of the compiled solve of a four-bar; most
callers read none of them. `kincas.sweep` hands `Sweep._built` None for "every pose ok" and
"no flag" and the kernel's float counts; the Sweep keeps a `_Later` for each, whose array is
made on the first read, once, and kept in its place (under a lock: two threads reading at
once get the same array, so a change made to it stays the Sweep's). What users see is
unchanged: `status` is an object array, `flags` a list, `iterations` integers; a set
replaces them as before.

>>> class Fields:
...     status = _lazy_field("status", "statuses")
>>> r = Fields()
>>> r.__dict__["_status"] = _Later(all_ok, 3)
>>> r.status.tolist(), r.status is r.status
(['ok', 'ok', 'ok'], True)
>>> angle_names(("C.x", "crank.angle", "d(crank.angle)/d(a)", "cam.phi"))
('crank.angle', 'cam.phi')
"""
from __future__ import annotations

import functools
import threading

import numpy as np


# A result's array made when first read (`Sweep._built`): `_Later(make, *args)`, a
# functools.partial (made in C: a class of our own with an __init__ cost three times as much,
# three a sweep); the field holds it until first read, then the array it made (`_made`).
_Later = functools.partial


_LATER = threading.Lock()


def all_ok(n: int) -> np.ndarray:
    status = np.empty(n, dtype=object)  # (np.full of an object is ten times slower)
    status.fill("ok")
    return status


def no_flags(n: int) -> list:
    return [None] * n


def whole(a: np.ndarray) -> np.ndarray:
    return a.astype(int)


def trues(n: int) -> np.ndarray:
    """n times True, a new array (np.ones costs three times as much)."""
    out = np.empty(n, dtype=bool)
    out.fill(True)
    return out


def wrap_angle(a: np.ndarray) -> np.ndarray:
    """Wrap radians to (-pi, pi]."""
    w = np.mod(np.asarray(a, dtype=float) + np.pi, 2 * np.pi) - np.pi
    return np.where(w == -np.pi, np.pi, w)


def wrap_angles(values: dict) -> None:
    """The angles among a result's values (`angle_names`) wrapped into (-pi, pi], in place."""
    for k in angle_names(tuple(values)):
        values[k] = wrap_angle(values[k])


def built(cls, n: int, status, flags, iterations, fields: dict):
    """A sweep's result as `kincas.sweep` builds it (`Sweep._built`), without `__init__`'s
    checks: `fields` (name -> value, a dict of the caller's own) becomes its attributes;
    status None (every pose "ok"), flags None (none) and float iterations are made when
    first read; the angles reported are wrapped. (A dict handed over, not keywords: a call
    with a dozen keywords and the copy of them cost as much as the rest.)"""
    out = cls.__new__(cls)
    fields["_status"] = _Later(all_ok, n) if status is None else status
    fields["_flags"] = _Later(no_flags, n) if flags is None else flags
    fields["_iterations"] = iterations if iterations.dtype.kind == "i" else _Later(whole, iterations)
    wrap_angles(fields["values"])
    out.__dict__ = fields
    return out


_ANGLES: dict = {}  # reported names (a tuple) -> those that are angles, wrapped into (-pi, pi]


def angle_names(names: tuple) -> tuple:
    """The names among `names` whose values are angles taken into (-pi, pi] (`.angle` and
    `.phi`, not derivatives `d(...)`), looked up once per list of names."""
    out = _ANGLES.get(names)
    if out is None:
        out = tuple(k for k in names if type(k) is str and k.endswith((".angle", ".phi")) and not k.startswith("d("))
        if len(_ANGLES) >= 256:  # (bounded: a loop over many lists)
            _ANGLES.clear()
        _ANGLES[names] = out
    return out


def _lazy_field(name: str, doc: str, convert=None):
    """A Sweep field kept as `_name`: read through `_Later` where it is made when first read;
    set (by __init__ too) through `convert`."""
    key = "_" + name

    def get(self):
        v = self.__dict__[key]
        return _made(self.__dict__, key) if type(v) is _Later else v

    def set(self, value):
        self.__dict__[key] = value if convert is None else convert(value)
    get.__doc__ = doc
    return property(get, set, doc=doc)


def _made(d: dict, key: str):
    """The value of field `key` left for later (a `_Later` in `d`, a result's __dict__), made
    by the first thread to read it and kept in its place; the others get the same object."""
    with _LATER:
        v = d[key]
        if type(v) is _Later:
            v = d[key] = v()
    return v


def _object_status(st):
    # object dtype: a longer status assigned later is kept whole, not truncated
    if isinstance(st, np.ndarray) and st.dtype == object:  # (kept if it is one)
        return st
    return st.astype(object) if isinstance(st, np.ndarray) else np.array(list(st), dtype=object)


def install(Sweep) -> None:
    """Sweep's status, flags and iterations as properties made when first read where
    `Sweep._built` leaves them for later (a dataclass's __init__ sets them through them)."""
    Sweep._built = classmethod(built)
    _SWEEP_EXAMPLE = """
        Examples
        --------
        >>> import kincas
        >>> m = kincas.Mechanism(ground={"O": (0, 0)}, links=[kincas.Link.bar("crank", "O", "A", 2)],
        ...                      inputs=[kincas.Input.angle("crank")])
        >>> sw = kincas.sweep(m, {"crank.angle": [0.0, 1.5707963267948966]}, report=["A.x"])
        >>> %s
        %s
        """
    Sweep.status = _lazy_field("status", """Per pose, "ok" or why it was not solved: a numpy array of
        strings (object dtype: a longer status assigned later is kept whole).
    """ + _SWEEP_EXAMPLE % ("sw.status.tolist(), sw.status.dtype", "(['ok', 'ok'], dtype('O'))"), _object_status)
    Sweep.flags = _lazy_field("flags", """Per pose, "limit", "change point" or "singular" at or next to a
        singular position, else None (a list).
    """ + _SWEEP_EXAMPLE % ("sw.flags", "[None, None]"))
    Sweep.iterations = _lazy_field("iterations", """Per pose, the Newton steps taken (integers; 0
        where none was attempted).
    """ + _SWEEP_EXAMPLE % ("sw.iterations.dtype.kind, bool((sw.iterations >= 0).all())", "('i', True)"))
