"""A scene's title and `[parameters]`: numbers, or `{ value = v, range = [lo, hi] }` tables whose
range is the span of `kincas app`'s slider. A mixin of the scene readers (planar and spatial):
the problems go to the reader's `err`, the values to `self.params`, the ranges to `self.ranges`.
"""
from __future__ import annotations

import math

LARGEST = 1e100  # beyond it, squared lengths overflow double precision


class ParameterReader:
    """The title and `[parameters]` of a scene (reader methods: `err`, `fields`, `table`)."""

    def ranged(self, name: str, v):
        """A parameter's value; the table form `{ value = 130, range = [100, 160] }` also
        gives the range a slider of `kincas app` spans (kept in `Study.ranges`). None when the
        table is wrong (the problem is noted, the parameter reported once)."""
        if not isinstance(v, dict):
            return v
        where = f"[parameters] {name}"
        self.fields(where, v, {"value", "range"})
        if "value" not in v:
            self.err(f"{where}: value: missing (the table form is {{ value = v, range = [lo, hi] }})")
            self.bad_params.add(name)
            return None
        r = v.get("range")
        if r is not None:
            good = (isinstance(r, list) and len(r) == 2
                    and all(isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)
                            for x in r) and r[0] < r[1])
            if not good:
                self.err(f"{where}: range: expected [lo, hi], two finite numbers with lo < hi, got {r!r}")
            elif isinstance(v["value"], (int, float)) and not r[0] <= v["value"] <= r[1]:
                self.err(f"{where}: value {v['value']!r} is outside its range {r!r}")
            else:
                self.ranges[name] = (float(r[0]), float(r[1]))
        return v["value"]

    def title_and_parameters(self) -> str:
        """The scene's title (checked) and its `[parameters]`, read into `self.params`."""
        doc = self.doc
        title = doc.get("title", "")
        if not isinstance(title, str):
            self.err("title: expected a string")
        for k, v in self.table("parameters").items():
            v = self.ranged(k, v)
            if v is None:
                continue
            if isinstance(v, bool) or not isinstance(v, (int, float)):
                self.err(f"[parameters] {k}: expected a number, got {v!r}")
                self.bad_params.add(k)
            elif not math.isfinite(v) or abs(v) > LARGEST:
                self.err(f"[parameters] {k}: {v} is not a finite number" if not math.isfinite(v)
                         else f"[parameters] {k}: {v:g} is too large (at most {LARGEST:g})")
                self.bad_params.add(k)
            else:
                self.params[k] = float(v)
        return title
