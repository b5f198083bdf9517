"""Loads that are expressions of the state and the time, for forward dynamics.

A load's component may be an expression in the `[optimize]` language (kincas/synthesis/
expressions.py: numbers, `+ - * / ^`, sin cos ... hypot) with, in addition:

- `t`, the time; `%`, the remainder of a division with the divisor's sign (Python's, so
  `crank.angle % 720` lies in [0, 720));
- quantities of positions and velocities at the current state: `P.x`, `P.vx`, `L.angle`,
  `L.omega`, `S.s`, `S.v` (an acceleration would make the loads depend on what they cause);
  angles are taken continuous (unwrapped), in the caller's angle unit;
- `[data]` lists, by name (`xs`) or as a table's column (`gas.angle`), only inside
  `interp(x, xs, ys)`: linear interpolation in the table (np.interp's: constant beyond its
  ends), whose derivative is exact piecewise;
- `min(a, b, ...)`, `max(a, b, ...)` of values (not the `[optimize]` extremes over a range).

Parsing and checking need no CasADi (scenes are read without it); the expression becomes a
CasADi expression in (q, u, u', t, p), so the equations of motion
stay one graph and their derivatives are exact.

>>> e = LoadExpression("T0 * (1 - crank.omega / w0) + interp(crank.angle % 720, g.a, g.f)",
...                    "[[loads]] 1: torque", data={"g.a": [0, 720], "g.f": [0, 1]})
>>> e.quantities, e.names, sorted(e.periods)
(['crank.omega', 'crank.angle'], ['T0', 'w0'], [('crank.angle', 720.0)])
"""
from __future__ import annotations

import ast
import math

import numpy as np

from ..errors import ModelError
from .expressions_sym import BINARY, UNARY, quantity_name

FUNCTIONS = UNARY | BINARY | {"interp", "min", "max"}
_OPS = (ast.Add, ast.Sub, ast.Mult, ast.Div, ast.Pow, ast.Mod)


class LoadExpression:
    """One expression, parsed and checked: the quantities, parameters and data it names, and
    the periods it reduces a quantity or the time by (`X % c`: (name of X, c))."""

    def __init__(self, text, where: str, data: dict):
        self.text, self.where, self.data = text, where, data
        if not isinstance(text, str) or not text.strip():
            raise ModelError(f"{where}: expected an expression (a string), got {text!r}")
        try:
            self.tree = ast.parse(text.replace("^", "**").strip(), mode="eval").body
        except SyntaxError as e:
            raise ModelError(f"{where}: cannot read {text!r}: {e.msg}") from None
        self.quantities, self.names, self.periods, self.uses_time = [], [], set(), False
        self._walk(self.tree, table=False)

    def _fail(self, msg):
        raise ModelError(f"{self.where}: {msg}")

    def _walk(self, node, table: bool):
        if isinstance(node, ast.Constant):
            if isinstance(node.value, bool) or not isinstance(node.value, (int, float)):
                self._fail(f"{node.value!r} is not a number")
        elif isinstance(node, (ast.Name, ast.Attribute)):
            name = node.id if isinstance(node, ast.Name) else quantity_name(node)
            if name is None:
                self._fail(f"{ast.unparse(node)!r} is not a quantity name (OBJECT.attribute)")
            if (name in self.data) != table:
                self._fail(f"{name!r}: interp(x, xs, ys) takes [data] lists as xs and ys, and a "
                           f"[data] list goes nowhere else" + ("" if name in self.data else
                                                               f" (no list {name!r} in [data])"))
            if name in self.data:
                return
            if name == "t":
                self.uses_time = True
            elif isinstance(node, ast.Attribute):
                self.quantities.append(name) if name not in self.quantities else None
            elif name != "pi":
                self.names.append(name) if name not in self.names else None
        elif isinstance(node, ast.BinOp) and isinstance(node.op, _OPS):
            if isinstance(node.op, ast.Mod) and isinstance(node.right, ast.Constant):
                left = ast.unparse(node.left)
                if left == "t" or quantity_name(node.left):
                    self.periods.add((left, float(node.right.value)))
            self._walk(node.left, False), self._walk(node.right, False)
        elif isinstance(node, ast.UnaryOp) and isinstance(node.op, (ast.USub, ast.UAdd)):
            self._walk(node.operand, False)
        elif isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and not node.keywords:
            f, n = node.func.id, len(node.args)
            if f not in FUNCTIONS:
                self._fail(f"unknown function {f!r} (allowed: {', '.join(sorted(FUNCTIONS))})")
            want = "3" if f == "interp" else "1" if f in UNARY else "2" if f in BINARY else "2 or more"
            if (n < 2) if f in ("min", "max") else n != int(want):
                self._fail(f"{f}() takes {want} argument(s)")
            for k, a in enumerate(node.args):
                self._walk(a, table=(f == "interp" and k > 0))
            if f == "interp":
                xs, ys = (self.data[ast.unparse(a)] for a in node.args[1:])
                if len(xs) != len(ys) or len(xs) < 2 or np.any(np.diff(xs) <= 0):
                    self._fail(f"interp(x, xs, ys): xs and ys must have the same length (2 or "
                               f"more) and xs must increase ({ast.unparse(node)!r})")
        else:
            self._fail(f"{ast.unparse(node)!r} is not allowed in a load's expression (numbers, "
                       f"names, + - * / ^ %, and functions)")

    def symbolic(self, leaf, time, angle: float):
        """The expression in CasADi: `leaf(kind, name)` gives a quantity's or a parameter's
        SX value; `time` the time's; `angle` is the caller's angle unit in radians."""
        return self._eval(self.tree, leaf, time, angle)

    def _eval(self, node, leaf, time, k):
        import casadi as ca  # here only: a scene's expressions are checked without CasADi
        ev = lambda a: self._eval(a, leaf, time, k)  # noqa: E731
        if isinstance(node, ast.Constant):
            return ca.SX(float(node.value))
        if isinstance(node, ast.Name):
            return time if node.id == "t" else ca.SX(math.pi) if node.id == "pi" else leaf("parameter", node.id)
        if isinstance(node, ast.Attribute):
            return leaf("quantity", quantity_name(node))
        if isinstance(node, ast.UnaryOp):
            return -ev(node.operand) if isinstance(node.op, ast.USub) else ev(node.operand)
        if isinstance(node, ast.BinOp):
            a, b = ev(node.left), ev(node.right)
            op = type(node.op)
            if op is ast.Mod:
                return a - b * ca.floor(a / b)
            return {ast.Add: a + b, ast.Sub: a - b, ast.Mult: a * b, ast.Div: a / b}[op] \
                if op is not ast.Pow else a ** b
        f, args = node.func.id, node.args
        if f == "interp":
            x = ev(args[0])
            xs, ys = (np.asarray(self.data[ast.unparse(a)], float) for a in args[1:])
            return ca.pw_lin(ca.fmin(ca.fmax(x, xs[0]), xs[-1]), ca.DM(xs), ca.DM(ys))
        vals = [ev(a) for a in args]
        if f in ("min", "max"):
            out = vals[0]
            for v in vals[1:]:
                out = ca.fmin(out, v) if f == "min" else ca.fmax(out, v)
            return out
        if f == "atan2":
            return ca.atan2(vals[0], vals[1]) / k
        if f == "hypot":
            return ca.sqrt(vals[0] ** 2 + vals[1] ** 2)
        if f in ("sin", "cos", "tan"):
            return getattr(ca, f)(vals[0] * k)
        if f in ("asin", "acos", "atan"):
            return getattr(ca, f)(vals[0]) / k
        return {"sqrt": ca.sqrt, "exp": ca.exp, "log": ca.log, "abs": ca.fabs}[f](vals[0])


def substituted(sym, q, u, ud, t, p, expressions: dict, k: float):
    """p with each expression's parameter replaced by the expression in (q, u, u', t, p):
    its quantities are those of the state (q, u, u'), angles continuous as q and u carry them,
    in the caller's angle unit (`k` radians); `expressions` maps parameter -> LoadExpression."""
    import casadi as ca
    from ..model.names import is_angular, parse_quantity
    if not expressions:
        return p
    names = []
    for e in expressions.values():
        for n in e.quantities:
            kind, obj, attr = parse_quantity(n)
            e_, order = sym.position_expr(obj, attr)
            if e_ is None or order > 1:
                raise ModelError(f"{e.where}: {n!r}: a load may depend on positions and "
                                 f"velocities (P.x, P.vx, L.angle, L.omega, S.s, S.v)")
            names.append(n) if n not in names else None
    vals = sym.quantity_function(names)(q, u, p, ud, ca.SX.zeros(sym.nu)) if names else ca.SX(0, 1)
    driven = {i.target: j for j, i in enumerate(sym.mech.inputs) if i.kind == "parameter"}
    hidden = set(expressions)
    where = ""

    def leaf(kind, name):
        if kind == "quantity":
            v = vals[names.index(name)]
            return v / k if is_angular(name, sym.mech) else v
        if name in hidden or name not in sym.pnames:
            raise ModelError(f"{where}: unknown name {name!r} (parameters: "
                             f"{[n for n in sym.pnames if n not in hidden and not n.startswith('_')]}, quantities, t, pi)")
        return u[driven[name]] if name in driven else p[sym.pnames.index(name)]

    out = ca.SX(p)
    for name, e in expressions.items():
        if name not in sym.pnames:
            raise ModelError(f"{e.where}: {name!r} is not a parameter of the mechanism")
        where = e.where
        out[sym.pnames.index(name)] = e.symbolic(leaf, t, k)
    return out


def load_dependence(model, names: list[str], hidden: list[str]) -> dict[str, list[str]]:
    """Which of the quantities `names` of a model (kincas.core.numeric.Model) depend on the
    parameters `hidden` (those standing for expressions), and on which: name -> hidden
    parameters (only names that depend on some). Read off the symbolic graph: kinematics never
    do; efforts, reactions, shaking forces and contact forces do where the load acts on them."""
    import casadi as ca
    if not names or not hidden:
        return {}
    sym = model.sym
    q, u, p, ud, udd = (ca.SX.sym(n, k) for n, k in (("q", sym.nq), ("u", sym.nu), ("p", sym.np),
                                                     ("ud", sym.nu), ("udd", sym.nu)))
    rows = sym.quantity_function(list(names))(q, u, p, ud, udd)
    out = {}
    for i, n in enumerate(names):
        on = [h for h in hidden if ca.depends_on(rows[i], p[sym.pnames.index(h)])]
        if on:
            out[n] = on
    return out


def loaded_function(model, names: list[str], expressions: dict, k: float):
    """f(q, u, p, u', u'', t) -> the quantities `names` with every expression's parameter
    replaced by the expression at that state (kincas/core/dynamics.py's kinetostatics with
    the loads as they are at the pose); built once per model, names and expressions."""
    import casadi as ca

    def build():
        sym = model.sym
        q, u, p, ud, udd = (ca.SX.sym(n, k_) for n, k_ in (("q", sym.nq), ("u", sym.nu), ("p", sym.np),
                                                          ("ud", sym.nu), ("udd", sym.nu)))
        t = ca.SX.sym("t")
        p_eff = substituted(sym, q, u, ud, t, p, expressions, k)
        rows = sym.quantity_function(list(names))(q, u, p_eff, ud, udd)
        return ca.Function("loaded", [q, u, p, ud, udd, t], [rows])
    key = ("loaded", tuple(names), tuple((n, e.text, e.where) for n, e in expressions.items()),
           tuple((n, tuple(v)) for e in expressions.values() for n, v in sorted(e.data.items())), k)
    return model.memo(key, build)


def data_lists(raw, where: str = "[data]") -> dict[str, list[float]]:
    """`[data]` as named lists: `xs = [...]` gives `xs`, `gas = { angle = [...] }` gives
    `gas.angle`. ModelError naming the entry when one is not a list of finite numbers.

    >>> data_lists({"xs": [0, 1], "gas": {"angle": [0, 30]}})
    {'xs': [0.0, 1.0], 'gas.angle': [0.0, 30.0]}
    """
    if not isinstance(raw, dict):
        raise ModelError(f"{where}: expected a table of named lists")
    out = {}
    for k, v in raw.items():
        items = v.items() if isinstance(v, dict) else [(None, v)]
        for c, xs in items:
            name = k if c is None else f"{k}.{c}"
            ok = isinstance(xs, list) and xs and all(
                isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x) for x in xs)
            if not ok:
                raise ModelError(f"{where} {name}: expected a list of finite numbers")
            out[name] = [float(x) for x in xs]
    return out
