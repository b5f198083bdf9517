"""The interface every result of kincas implements (as sympy.physics.mechanics declares one).

A solve, a sweep, a designs' sweep, a study, assembly modes, a range of motion, a tolerance
analysis, sensitivities and an optimisation each return an object that

- says whether it succeeded in itself (`ok`: a bool, or one per pose / design): a failure is
  reported in the result, never raised (as scipy's OptimizeResult does);
- converts to pandas and xarray with the same keywords (`to_pandas(length="", angle="rad")`,
  `to_xarray(...)`: `length` names the unit of lengths in the units recorded, `angle="deg"`
  converts angles, angular rates and derivatives of angles to degrees);
- prints as one line saying what it holds (`repr`, built from `summary()`).

>>> import kincas
>>> m = kincas.Mechanism(ground={"O": (0, 0)}, links=[kincas.Link.bar("crank", "O", "A", 2)],
...                      inputs=[kincas.Input.angle("crank")])
>>> r = kincas.sweep(m, {"crank.angle": [0.0, 1.0]}, report=["A.x"])
>>> isinstance(r, Result), r.ok.tolist()
(True, [True, True])
"""
from __future__ import annotations

import abc


class Result(abc.ABC):
    """What every public result offers: `ok`, `to_pandas`, `to_xarray`, `summary` and a
    one-line `repr`.

    Examples
    --------
    >>> import numpy as np
    >>> class Tiny(Result):
    ...     ok = True
    ...     def summary(self): return "one number"
    ...     def to_pandas(self, length="", angle="rad"): return None
    ...     def to_xarray(self, length="", angle="rad"): return None
    >>> Tiny()
    <Tiny: one number>
    """

    @property
    @abc.abstractmethod
    def ok(self):
        """Whether it succeeded: a bool, or a boolean array (one per pose or design)."""

    @abc.abstractmethod
    def summary(self) -> str:
        """A short description of what the result holds (the body of its `repr`)."""

    @abc.abstractmethod
    def to_pandas(self, length: str = "", angle: str = "rad"):
        """A pandas DataFrame; `length` names the unit of lengths in `df.attrs["units"]`;
        `angle="deg"` gives angles, angular rates and derivatives of angles in degrees."""

    @abc.abstractmethod
    def to_xarray(self, length: str = "", angle: str = "rad"):
        """An xarray Dataset; `length` names the unit of lengths in each variable's units;
        `angle="deg"` gives angles, angular rates and derivatives of angles in degrees."""

    def __repr__(self) -> str:
        return f"<{type(self).__name__}: {self.summary()}>"


# Every public result type, by the one name it goes by (what it holds, as `Sweep` and `Pose`
# do), and where it lives: `kincas.Study` etc. load the module on first use.
TYPES = {"Result": "result_base", "Pose": "results", "Sweep": "results",
         "DesignSweep": "analysis.designs", "Study": "synthesis.study",
         "Sensitivities": "analysis.sensitivity", "ToleranceAnalysis": "analysis.tolerance",
         "Optimization": "synthesis.optimize", "Multistart": "synthesis.multistart",
         "Modes": "frames", "Range": "analysis.singular", "Simulation": "analysis.simulate"}
# their names in kincas 0.1, served one more release with a DeprecationWarning
RENAMED = {"StudyResult": "Study", "ToleranceResult": "ToleranceAnalysis",
           "OptimizeResult": "Optimization", "MultistartResult": "Multistart"}


def result_type(name: str):
    """The result class `kincas.<name>` (an old name warns and gives the new one).

    Parameters
    ----------
    name : str
        A name of `TYPES` or `RENAMED`.

    Returns
    -------
    type

    Examples
    --------
    >>> import warnings
    >>> with warnings.catch_warnings(record=True) as w:
    ...     warnings.simplefilter("always")
    ...     result_type("StudyResult").__name__, w[0].category.__name__
    ('Study', 'DeprecationWarning')
    """
    import importlib
    import warnings

    if name in RENAMED:
        warnings.warn(f"kincas.{name} is deprecated: use kincas.{RENAMED[name]} (the old name "
                      f"goes in the next release)", DeprecationWarning, stacklevel=3)
        name = RENAMED[name]
    return getattr(importlib.import_module(f"kincas.{TYPES[name]}"), name)


def listed(d, most: int = 4) -> str:
    """'a, b, c' or 'a, b, c, d and 5 more' (the names of `d`, at most `most` of them).

    >>> listed("abcdef", 4)
    'a, b, c, d and 2 more'
    """
    names = list(d)
    if len(names) <= most:
        return ", ".join(names)
    return ", ".join(names[:most]) + f" and {len(names) - most} more"
