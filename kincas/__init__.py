"""kincas: kinematics and motion of closed-chain mechanisms, planar and spatial, solved as a
whole with CasADi.

Declare a mechanism (ground points, links, slides, inputs), then solve poses or sweeps:
positions by Newton with the exact Jacobian, velocities and accelerations from the same
Jacobians, sensitivities to every named parameter. Angles are radians in Python.

>>> import numpy as np, kincas
>>> m = kincas.Mechanism(ground={"A": (0, 0), "D": (4, 0)},
...     links=[kincas.Link.bar("crank", "A", "B", 1), kincas.Link.bar("coupler", "B", "C", 3.5),
...            kincas.Link.bar("rocker", "D", "C", 3)],
...     inputs=[kincas.Input.angle("crank")], guess={"C": (3.6, 2.9)})
>>> pose = kincas.solve(m, {"crank.angle": np.pi / 2}, report=["C.x", "rocker.omega"])
>>> pose.status, round(pose["C.x"], 6)
('ok', 2.987219)
"""
try:  # Ctrl-C while Python loads kincas (about a second): the command says one line, not a traceback
    from . import _aliases
    from .errors import KincasError, ModelError, SceneError
    from .model import Input, Link, Load, Mechanism, Param, Slide
    from .model.space import SpatialMechanism
    from .model.space_parts import Body, Joint, SpatialSlide
    from .results import Pose, Sweep
    from .core.numeric import model_of
    from .analysis.sweeps import solve, sweep
    from .analysis.methods import Careful, Fast, SweepMethod
    from . import views
    from .model import mechanism as _mechanism
    from .core.numeric import redundant_equations as _redundant_equations
    # sweep_designs and study are loaded on first use (kincas._aliases): `kincas solve` and
    # plain sweeps do not pay for their imports (thread pools, logging, dask hooks)

    _aliases.install()  # `import kincas.modes` and other paths of the flat 0.1 layout
    # the face wires the floors together: the model and the results never import the solver or
    # their views, and no floor edits another's objects (tests/test_layering.py)
    _mechanism.use_rank_test(_redundant_equations)  # Mechanism.redundant, where counting cannot tell
    Mechanism._repr_svg_ = views.mechanism_svg_display  # Jupyter's displays
    Sweep._repr_html_ = views.sweep_html_display
except KeyboardInterrupt:
    from ._launch import interrupted_while_loading
    interrupted_while_loading()  # exits 130 where kincas runs as the command; otherwise:
    raise


def __getattr__(name):
    from .result_base import RENAMED, TYPES, result_type
    if name in TYPES or name in RENAMED:  # kincas.Study, kincas.Range, ... (old names warned)
        return result_type(name)
    if name == "compile":  # 0.1's name of model_of: it compiles nothing, shadows the builtin
        from ._deprecated import renamed  # and is not sweep(compile=...), which does compile
        return renamed(globals(), {"compile": "model_of"}, "kincas")(name)
    return _aliases.attribute(name)


__all__ = ["Mechanism", "Link", "Slide", "Input", "Param", "Load", "solve", "sweep",
           "SpatialMechanism", "Body", "Joint", "SpatialSlide",
           "SweepMethod", "Fast", "Careful",
           "sweep_designs", "study", "model_of",
           "sensitivities", "analyse", "optimize", "modes", "find_modes", "input_range", "simulate",
           "Pose", "Sweep", "KincasError", "ModelError", "SceneError", "widget"]
__version__ = "0.1.0"
