"""Results as pandas DataFrames and xarray Datasets (the optional extra `kincas[data]`).

`Sweep.to_pandas()`: one row per pose, the inputs as the index (a MultiIndex when several
inputs advance together), a column per reported quantity, then `status` and `flag`.
`Sweep.to_xarray()`: a Dataset along the dimension `pose`, the inputs as coordinates, each
quantity a variable with its unit in `attrs["units"]`. Tolerance analyses, assembly modes and
optimisations convert the same way. Values are as the result holds them: angles in radians,
lengths in the mechanism's own unit (name it with `length="mm"`).

>>> import numpy as np, kincas
>>> m = kincas.Mechanism(ground={"A": (0, 0), "D": (4, 0)},
...     links=[kincas.Link.bar("crank", "A", "B", 1), kincas.Link.bar("coupler", "B", "C", 3.5),
...            kincas.Link.bar("rocker", "D", "C", 3)],
...     inputs=[kincas.Input.angle("crank")], guess={"C": (3.6, 2.9)})
>>> sw = kincas.sweep(m, {"crank.angle": np.linspace(0, np.pi, 3)}, report=["C.x", "rocker.omega"])
>>> df = sw.to_pandas()
>>> df.index.name, list(df.columns), df["status"].tolist()
('crank.angle', ['C.x', 'rocker.omega', 'status', 'flag'], ['ok', 'ok', 'ok'])
>>> sw.to_xarray(length="mm")["C.x"].attrs["units"]
'mm'
"""
from __future__ import annotations

import importlib

import numpy as np

from .model.names import attr_base, derivative_order
from .result_base import Result



def require(package: str):
    """Import pandas or xarray, or say in one line how to get them."""
    try:
        return importlib.import_module(package)
    except ModuleNotFoundError:
        raise ModuleNotFoundError(f"this needs {package}, which is not installed: "
                                  f'pip install "kincas[data]"', name=package) from None


def unit_of(name: str, length: str = "", angle: str = "rad", time: str = "s") -> str:
    """The unit of a quantity or input key as a result holds it ('' when it has none or is
    not known here).

    >>> unit_of("rocker.alpha"), unit_of("C.vx", "mm"), unit_of("d(C.x)/d(a)", "mm")
    ('rad/s^2', 'mm/s', 'mm/mm')
    """
    if name.startswith("d(") and ")/d(" in name:
        q = name[2:name.index(")/d(")]
        uq = unit_of(q, length, angle, time)
        return f"{uq or '1'}/{length}" if length else uq
    if name.startswith("shaking."):  # a force or moment: no force unit is known here
        return ""
    attr = name.rsplit(".", 1)[-1] if "." in name else None
    order = derivative_order(attr) if attr else None
    if order is None:
        return length if "." not in name else ""  # a parameter driven by an input: a length
    angular = attr_base(attr) in ("angle", "omega", "alpha", "jerk")
    base = angle if angular else length
    if not base:
        return ""
    return base + ("" if order == 0 else f"/{time}" if order == 1 else f"/{time}^{order}")


def _index(pd, inputs: dict, n: int):
    keys = list(inputs)
    if not keys:
        return pd.RangeIndex(n, name="pose")
    if len(keys) == 1:
        return pd.Index(np.asarray(inputs[keys[0]], float), name=keys[0])
    return pd.MultiIndex.from_arrays([np.asarray(inputs[k], float) for k in keys], names=keys)


# --- sweeps ---


def sweep_to_pandas(sw, length: str = ""):
    return _poses_frame(sw.inputs, sw.values, sw.status, sw.flags, length)


def _poses_frame(inputs: dict, values: dict, status, flags, length: str):
    pd = require("pandas")
    # a reported quantity that is also an input (a driven link's angle) is the index, as the
    # input was given (unwrapped), not a second column of that name (as in to_xarray)
    cols = {k: np.asarray(v, float) for k, v in values.items() if k not in inputs}
    cols["status"] = np.asarray(status).astype(str)
    cols["flag"] = pd.array([f if f else None for f in flags], dtype="object")
    df = pd.DataFrame(cols, index=_index(pd, inputs, len(cols["status"])))
    df.attrs["units"] = {k: unit_of(k, length) for k in [*inputs, *values]}
    return df


def sweep_to_xarray(sw, length: str = ""):
    return _poses_dataset(sw.inputs, sw.values, sw.status, sw.flags, sw.residual, length,
                          {"size": float(sw.size)})


def _poses_dataset(inputs: dict, values: dict, status, flags, residual, length: str, attrs=None):
    xr = require("xarray")
    coords = {k: ("pose", np.atleast_1d(np.asarray(v, float)), {"units": unit_of(k, length)})
              for k, v in inputs.items()}
    data = {k: ("pose", np.atleast_1d(np.asarray(v, float)), {"units": unit_of(k, length)})
            for k, v in values.items() if k not in inputs}
    status = np.asarray(status).astype(str)
    data["status"] = ("pose", status)
    data["flag"] = ("pose", np.array([f or "" for f in flags], dtype=str))
    data["ok"] = ("pose", status == "ok")
    data["residual"] = ("pose", np.atleast_1d(np.asarray(residual, float)),
                        {"description": "loop-closure residual relative to the size"})
    return xr.Dataset(data, coords=coords, attrs=attrs or {})


def pose_to_pandas(pose, length: str = ""):
    return _poses_frame({k: [v] for k, v in pose.inputs.items()},
                        {k: [v] for k, v in pose.values.items()}, [pose.status], [pose.flag], length)


def pose_to_xarray(pose, length: str = ""):
    return _poses_dataset(pose.inputs, pose.values, [pose.status], [pose.flag], [pose.residual], length)


# --- tolerance analyses ---


def tolerance_to_pandas(r, length: str = ""):
    pd = require("pandas")
    cols = {}
    for n in r.names:
        if n not in r.inputs:  # an input is the index
            cols[n] = np.asarray(r.nominal[n], float)
        cols[f"std {n}"] = np.asarray(r.first_order[n], float)
        cols[f"mc {n}"] = np.asarray(r.monte_carlo[n], float)
    cols["status"] = np.asarray(r.status).astype(str)
    cols["failed"] = np.asarray(r.failed, int)
    df = pd.DataFrame(cols, index=_index(pd, r.inputs, len(r.status)))
    df.attrs.update(draws=r.draws, samples=r.draws, seed=r.seed, std=dict(r.std),
                    units={n: unit_of(n, length) for n in [*r.inputs, *r.names]})
    return df


def tolerance_to_xarray(r, length: str = ""):
    xr = require("xarray")
    stack = lambda d: np.stack([np.asarray(d[n], float) for n in r.names], axis=1)
    coords = {k: ("pose", np.asarray(v, float), {"units": unit_of(k, length)}) for k, v in r.inputs.items()}
    coords["quantity"] = ("quantity", list(r.names))
    coords["units"] = ("quantity", [unit_of(n, length) for n in r.names])
    data = {"nominal": (("pose", "quantity"), stack(r.nominal)),
            "first_order": (("pose", "quantity"), stack(r.first_order),
                            {"description": "first-order std from the exact sensitivities"}),
            "monte_carlo": (("pose", "quantity"), stack(r.monte_carlo),
                            {"description": "Monte-Carlo std"}),
            "status": ("pose", np.asarray(r.status).astype(str)),
            "failed": ("pose", np.asarray(r.failed, int))}
    attrs = {"draws": int(r.draws), "samples": int(r.draws), **{f"std {p}": float(s) for p, s in r.std.items()}}
    if r.seed is not None:
        attrs["seed"] = int(r.seed)
    return xr.Dataset(data, coords=coords, attrs=attrs)


# --- assembly modes ---


def _mode_columns(modes) -> dict:
    cols: dict[str, list] = {}
    for md in modes:
        for p, (x, y) in md.points.items():
            cols.setdefault(f"{p}.x", []).append(float(x))
            cols.setdefault(f"{p}.y", []).append(float(y))
        for lk, a in md.angles.items():
            cols.setdefault(f"{lk}.angle", []).append(float(a))
    cols["residual"] = [float(md.residual) for md in modes]
    cols["orientation"] = [int(md.orientation) for md in modes]
    cols["from_guess"] = [bool(md.from_guess) for md in modes]
    return cols


def modes_to_pandas(modes, length: str = ""):
    pd = require("pandas")
    df = pd.DataFrame(_mode_columns(modes), index=pd.RangeIndex(1, len(modes) + 1, name="mode"))
    df.attrs["units"] = {c: unit_of(c, length) for c in df.columns if "." in c}
    return df


def modes_to_xarray(modes, length: str = ""):
    xr = require("xarray")
    data = {c: ("mode", np.asarray(v), {"units": unit_of(c, length)} if "." in c else {})
            for c, v in _mode_columns(modes).items()}
    return xr.Dataset(data, coords={"mode": np.arange(1, len(modes) + 1)})


# --- optimisations ---


def optimize_to_pandas(r, length: str = ""):
    pd = require("pandas")
    n = len(next(iter(r.inputs.values()))) if r.inputs else 0
    df = pd.DataFrame({k: np.asarray(v, float) for k, v in r.values.items()},
                      index=_index(pd, r.inputs, n))
    df.attrs.update(parameters=dict(r.parameters), varied=dict(r.varied), objective=r.objective,
                    ok=r.ok, status=r.status, message=r.message,
                    units={k: unit_of(k, length) for k in [*r.inputs, *r.values]})
    return df


def optimize_to_xarray(r, length: str = ""):
    xr = require("xarray")
    coords = {k: ("sample", np.asarray(v, float), {"units": unit_of(k, length)}) for k, v in r.inputs.items()}
    data = {k: ("sample", np.asarray(v, float), {"units": unit_of(k, length)})
            for k, v in r.values.items() if k not in r.inputs}
    attrs = {"objective": float(r.objective), "ok": int(r.ok), "status": r.status,
             "message": r.message, "iterations": int(r.iterations),
             **{f"parameter {p}": float(v) for p, v in r.parameters.items()},
             "varied": ", ".join(r.varied)}
    return xr.Dataset(data, coords=coords, attrs=attrs)


# --- a list of modes that converts like the other results ---


class Modes(list, Result):
    """The assembly modes `find_modes` returns: a list of `Mode` (indexed, iterated and
    printed as a list), with `to_pandas()` (a row per mode: points, angles, residual,
    orientation, from_guess), `to_xarray()`, `ok` (some mode was found) and `summary()`;
    `certified` is False for the multistart search (kincas/analysis/certify.py proves it)."""

    certified = False

    @property
    def ok(self) -> bool:
        return len(self) > 0

    def summary(self) -> str:
        return (f"{len(self)} assembly modes" + ("" if self else " (none found)")
                + ("" if self.certified else " (multistart search, not certified)"))

    def to_pandas(self, length: str = "", angle: str = "rad"):
        return in_angle(modes_to_pandas(self, length), angle)

    def to_xarray(self, length: str = "", angle: str = "rad"):
        return in_angle(modes_to_xarray(self, length), angle)


# --- designs' sweeps (design x pose) and studies (one row per design) ---


def designs_to_pandas(r, length: str = ""):
    pd = require("pandas")
    nd, npose = r.code.shape
    index = pd.MultiIndex.from_product([range(nd), range(npose)], names=["design", "pose"])
    cols = {n: np.repeat(r.params[:, j], npose) for j, n in enumerate(r.names)}
    cols.update({k: np.tile(np.asarray(v, float), nd) for k, v in r.inputs.items()})
    cols.update({k: np.asarray(v, float).ravel() for k, v in r.values.items() if k not in r.inputs})
    cols["status"] = r.status.astype(str).ravel()
    df = pd.DataFrame(cols, index=index)
    df.attrs["units"] = {k: unit_of(k, length) for k in [*r.names, *r.inputs, *r.values]}
    return df


def designs_to_xarray(r, length: str = ""):
    xr = require("xarray")
    data = {n: (("design", "pose"), v, {"units": unit_of(n, length)}) for n, v in r.values.items()}
    data["status"] = (("design", "pose"), r.status.astype(str))
    coords = {n: ("design", r.params[:, j], {"units": unit_of(n, length)}) for j, n in enumerate(r.names)}
    coords.update({k: ("pose", v, {"units": unit_of(k, length)}) for k, v in r.inputs.items()})
    return xr.Dataset(data, coords=coords)


def study_to_pandas(r, length: str = ""):
    pd = require("pandas")
    df = pd.DataFrame(r.columns())
    df.index.name = "design"
    df.attrs["units"] = {n: unit_of(n, length) for n in r.names}  # the report's expressions: free
    return df


def study_to_xarray(r, length: str = ""):
    xr = require("xarray")
    data = {k: ("design", np.asarray(v, dtype=str if k == "status" else float),
                {"units": unit_of(k, length)} if k in r.names else {})
            for k, v in r.columns().items()}
    return xr.Dataset(data, coords={"design": np.arange(len(r.status))})


# --- a range of motion, sensitivities ---


def range_to_pandas(r, length: str = ""):
    pd = require("pandas")
    df = pd.DataFrame({"kind": [k for k, _ in r.limits], "value": [float(v) for _, v in r.limits]},
                      index=pd.RangeIndex(len(r.limits), name="limit"))
    df.attrs.update(key=r.key, low=float(r.low), high=float(r.high), full_turn=bool(r.full_turn),
                    start=float(r.start), units={r.key: unit_of(r.key, length)})
    return df


def range_to_xarray(r, length: str = ""):
    xr = require("xarray")
    data = {"kind": ("limit", np.array([k for k, _ in r.limits], dtype=str)),
            "value": ("limit", np.array([v for _, v in r.limits], dtype=float),
                      {"units": unit_of(r.key, length)})}
    attrs = {"key": r.key, "low": float(r.low), "high": float(r.high),
             "full_turn": int(r.full_turn), "start": float(r.start)}
    return xr.Dataset(data, attrs=attrs)


def sensitivities_to_pandas(s, length: str = ""):
    sw = s.sweep
    return _poses_frame(sw.inputs, {n: s[n] for n in s}, sw.status, sw.flags, length)


def sensitivities_to_xarray(s, length: str = ""):
    sw = s.sweep
    return _poses_dataset(sw.inputs, {n: s[n] for n in s}, sw.status, sw.flags, sw.residual, length)


def multistart_to_pandas(r, length: str = ""):
    pd = require("pandas")
    cols = {f"start {n}": np.asarray(r.starts)[:, j] for j, n in enumerate(r.names)}
    cols["objective"] = [float(o.objective) for o in r.results]
    cols["ok"] = [bool(o.ok) for o in r.results]
    cols["status"] = [str(o.status) for o in r.results]
    for n in r.names:
        cols[n] = [float(o.varied.get(n, np.nan)) for o in r.results]
    df = pd.DataFrame(cols, index=pd.RangeIndex(len(r.results), name="start"))
    df.attrs["units"] = {n: unit_of(n, length) for n in r.names}
    return df


# --- angles in degrees on request (every result's `angle="deg"`) ---


def _angle_factor(unit: str, angle: str) -> float:
    """What turns a value of `unit` (as recorded, radians) into `angle`'s unit: 180/pi for a
    unit whose numerator is radians (rad, rad/s, rad/mm), 1 otherwise."""
    return 180.0 / np.pi if angle == "deg" and unit.split("/")[0] == "rad" else 1.0


def _deg_unit(unit: str) -> str:
    return "deg" + unit[3:] if unit.split("/")[0] == "rad" else unit


def in_angle(table, angle: str = "rad"):
    """`table` (a DataFrame or Dataset made above, in radians) with its angles, angular rates
    and derivatives of angles in `angle` ("rad" : as it is, "deg" : degrees), units renamed.

    >>> import pandas as pd
    >>> df = pd.DataFrame({"L.angle": [np.pi]}); df.attrs["units"] = {"L.angle": "rad"}
    >>> t = in_angle(df, "deg"); float(t["L.angle"][0]), t.attrs["units"]
    (180.0, {'L.angle': 'deg'})
    """
    if angle not in ("rad", "deg"):
        from .errors import ModelError
        raise ModelError(f"angle: expected 'rad' or 'deg', got {angle!r}")
    if angle == "rad":
        return table
    table = table.copy()
    if hasattr(table, "data_vars"):  # an xarray Dataset: units on each variable and coordinate
        for name in [*table.data_vars, *table.coords]:
            unit = table[name].attrs.get("units", "")
            k = _angle_factor(unit, angle)
            if k != 1.0:
                table[name] = table[name] * k
                table[name].attrs["units"] = _deg_unit(unit)
        if "units" in table.coords and "quantity" in table.dims:  # per quantity (tolerances)
            k = np.array([_angle_factor(str(u), angle) for u in table["units"].values])
            for name in table.data_vars:
                if "quantity" in table[name].dims and table[name].dtype.kind == "f":
                    table[name] = table[name] * table["units"].copy(data=k)
            table = table.assign_coords(units=("quantity", [_deg_unit(str(u)) for u in table["units"].values]))
        return table
    units = dict(table.attrs.get("units", {}))  # a DataFrame: units by column (or index) name
    for col in table.columns:
        key = next((col[len(p):] for p in ("std ", "mc ") if str(col).startswith(p)), col)
        k = _angle_factor(units.get(key, ""), angle)
        if k != 1.0:
            table[col] = table[col] * k
    names = list(table.index.names)
    if any(_angle_factor(units.get(n, ""), angle) != 1.0 for n in names if n):
        levels = [table.index.get_level_values(i) * _angle_factor(units.get(n, ""), angle)
                  for i, n in enumerate(names)]
        import pandas as pd
        table.index = (pd.MultiIndex.from_arrays(levels, names=names) if len(names) > 1
                       else pd.Index(levels[0], name=names[0]))
    table.attrs["units"] = {n: _deg_unit(u) for n, u in units.items()}
    return table
