"""A scene written back as TOML (`kincas app`'s download of the edited scene): the parsed document
with its edits, written so that `tomllib` reads back the same document (comments are not kept:
tomllib drops them).

Top-level plain values first, then each table as a `[section]` whose entries are written on
one line each (nested tables as inline tables), and each array of tables as `[[section]]`
blocks.

>>> doc = {"title": "a \\"four\\"-bar", "parameters": {"r": 1.5, "a1": {"value": 130, "range": [100, 160]}},
...        "ground": {"A": [0, 0], "O 4": ["r", 0]}, "inputs": [{"angle": "crank", "value": 90}]}
>>> text = dumps(doc)
>>> tomllib.loads(text) == doc
True
>>> print(text.splitlines()[0])
title = "a \\"four\\"-bar"
"""
from __future__ import annotations

import datetime
import tomllib
import json
import math
import re

_BARE = re.compile(r"^[A-Za-z0-9_-]+$")


def key(k: str) -> str:
    """A key, bare where TOML allows it, else quoted."""
    return k if _BARE.match(k) else _string(k)


def _string(s: str) -> str:
    # JSON's escapes are TOML's (\", \\, \n, \uXXXX); DEL must be escaped in TOML too
    return json.dumps(s, ensure_ascii=False).replace("\x7f", "\\u007f")


def value(v) -> str:
    """One value, inline."""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if math.isnan(v):
            return "nan"
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return repr(v)
    if isinstance(v, str):
        return _string(v)
    if isinstance(v, (datetime.datetime, datetime.date, datetime.time)):
        return v.isoformat()
    if isinstance(v, dict):
        return "{ " + ", ".join(f"{key(k)} = {value(x)}" for k, x in v.items()) + " }" if v else "{}"
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(value(x) for x in v) + "]"
    raise TypeError(f"cannot write {type(v).__name__} as TOML")


def _tables(v) -> bool:
    return isinstance(v, list) and bool(v) and all(isinstance(x, dict) for x in v)


def dumps(doc: dict) -> str:
    """The document as TOML text."""
    head, body = [], []
    for k, v in doc.items():
        if isinstance(v, dict):
            body.append(f"\n[{key(k)}]")
            body += [f"{key(kk)} = {value(x)}" for kk, x in v.items()]
        elif _tables(v):
            for t in v:
                body.append(f"\n[[{key(k)}]]")
                body += [f"{key(kk)} = {value(x)}" for kk, x in t.items()]
        else:
            head.append(f"{key(k)} = {value(v)}")
    return "\n".join(head + body).lstrip("\n") + "\n"


def number(v: float, like=None):
    """`v` as an int where it is whole and `like` (the value it replaces) was an int."""
    v = float(v)
    if isinstance(like, int) and not isinstance(like, bool) and v.is_integer() and abs(v) < 2 ** 53:
        return int(v)
    return v


_HEADER = re.compile(r"^\s*(\[\[?)\s*([A-Za-z0-9_-]+)\s*\]\]?\s*(#.*)?$")
_ENTRY = re.compile(r"^(\s*)([A-Za-z0-9_-]+|\"[^\"]*\")(\s*=\s*)(.*?)(\s*(#.*)?)$")


def edited(text: str, old: dict, new: dict) -> str:
    """`text` (whose document is `old`) with the entries that differ in `new` written anew in
    place, so that its comments and layout stay: each changed `key = value` line of a table or
    of the n-th block of an array of tables gets the new value, its comment kept. Where that
    does not give exactly `new` (a value over several lines, a dotted key, a change of shape),
    the whole document is written afresh (`dumps`).

    >>> text = '[parameters]\\nr = 1   # crank\\n\\n[[inputs]]\\nangle = "crank"\\nvalue = 30\\n'
    >>> old = tomllib.loads(text)
    >>> new = {"parameters": {"r": 1.5}, "inputs": [{"angle": "crank", "value": 45}]}
    >>> print(edited(text, old, new), end="")
    [parameters]
    r = 1.5   # crank
    <BLANKLINE>
    [[inputs]]
    angle = "crank"
    value = 45
    """
    table, seen, out = None, {}, []
    for line in text.splitlines(keepends=True):
        body, end = (line[:-1], "\n") if line.endswith("\n") else (line, "")
        h = _HEADER.match(body)
        if h:
            name = h.group(2)
            if h.group(1) == "[[":
                seen[name] = seen.get(name, -1) + 1
                table = _get(new, name, seen[name]), _get(old, name, seen[name])
            else:
                table = new.get(name), old.get(name)
            out.append(line)
            continue
        if body.lstrip().startswith("["):  # a dotted table, or an array's line: not ours to edit
            table = None
        e = _ENTRY.match(body.rstrip("\r"))
        if e and table is not None and isinstance(table[0], dict) and isinstance(table[1], dict):
            k = e.group(2).strip('"')
            if k in table[0] and table[0][k] != table[1].get(k):
                line = f"{e.group(1)}{e.group(2)}{e.group(3)}{value(table[0][k])}{e.group(5)}" \
                       + ("\r" if body.endswith("\r") else "") + end
        out.append(line)
    result = "".join(out)
    try:
        if tomllib.loads(result) == new:
            return result
    except tomllib.TOMLDecodeError:
        pass
    return dumps(new)


def _get(doc: dict, name: str, i: int):
    v = doc.get(name)
    return v[i] if isinstance(v, list) and i < len(v) and isinstance(v[i], dict) else None
