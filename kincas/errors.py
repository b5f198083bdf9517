"""Errors for a user's mistakes: each names where the mistake is (section and field).

A malformed mechanism or scene raises one error that gathers *every* problem found, so
that a user fixes them all in one pass instead of one per run.

>>> from kincas.errors import ModelError
>>> str(ModelError(["[links] crank: missing `length`", "[guess] Z: unknown point"]))
'2 problems:\\n  [links] crank: missing `length`\\n  [guess] Z: unknown point'
"""
from __future__ import annotations


class KincasError(Exception):
    """Base class: a problem in what the user declared (never a bug of kincas).

    Parameters
    ----------
    problems : list of str or str
        Every problem found, each naming its section and field.

    Examples
    --------
    >>> e = KincasError(["[links] crank: missing `length`"])
    >>> e.problems, str(e)
    (['[links] crank: missing `length`'], '[links] crank: missing `length`')
    """

    def __init__(self, problems: list[str] | str):
        self.problems = [problems] if isinstance(problems, str) else list(problems)
        super().__init__(self._text())

    def _text(self) -> str:
        if len(self.problems) == 1:
            return self.problems[0]
        return f"{len(self.problems)} problems:\n" + "\n".join("  " + p for p in self.problems)


class ModelError(KincasError, ValueError):
    """The mechanism's declaration is inconsistent (unknown name, wrong mobility, ...).

    Parameters
    ----------
    problems : list of str or str
        Every problem found.

    Examples
    --------
    >>> import kincas
    >>> try:
    ...     kincas.Mechanism(ground={"A": (0, 0)}, links=[kincas.Link.bar("crank", "A", "B", -1)],
    ...                      inputs=[kincas.Input.angle("crank")])
    ... except kincas.ModelError as e:
    ...     print(e.problems[0])
    [links] crank: length must be positive
    """


class SceneError(KincasError, ValueError):
    """The scene file is malformed: the message names the section and the field.

    Parameters
    ----------
    problems : list of str or str
        Every problem found.

    Examples
    --------
    >>> from kincas.cli.scene import loads
    >>> try:
    ...     loads('ground = 3')
    ... except SceneError as e:
    ...     print(e.problems[0])
    [ground]: expected a table
    """


class OutputError(KincasError):
    """A file or option on the command line cannot be honoured (an unwritable path, a
    missing optional extra): the command says so in one line."""
