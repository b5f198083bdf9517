"""Ctrl-C while Python is still loading kincas, before the command's own handler exists.

`kincas solve ...` (the console script) and `python -m kincas ...` import the package first,
which takes about a second (numpy, CasADi); a Ctrl-C in that window used to end in a
KeyboardInterrupt traceback. The package's face catches it and calls
`interrupted_while_loading`: where kincas runs as the command, the command's usual line and
exit status 130 (what `kincas.cli.app.main` gives once it runs); in a notebook, a REPL or a
user's script the KeyboardInterrupt goes on as usual, since that caller may handle it.

How the command is recognised: the console script runs as `.../kincas` (`kincas.exe`,
`kincas-script.py` on Windows), and while `python -m kincas` imports the package Python
sets `sys.argv[0]` to "-m" (the docs of `sys.argv`). An interactive session never exits here.
"""
from __future__ import annotations

import os
import sys

EXIT_INTERRUPTED = 130  # the shell's usual status after Ctrl-C (kincas.cli.common takes it from here)
COMMAND_NAMES = ("kincas", "kincas.exe", "kincas-script.py")


def running_as_command(argv0: str | None = None) -> bool:
    """Whether this process is the `kincas` command (see the module text).

    >>> running_as_command("/usr/local/bin/kincas"), running_as_command("-m"), running_as_command("pytest")
    (True, True, False)
    """
    if hasattr(sys, "ps1") or sys.flags.interactive:
        return False
    a0 = (sys.argv[0] if sys.argv else "") if argv0 is None else argv0
    return a0 == "-m" or os.path.basename(a0) in COMMAND_NAMES


def exit_interrupted() -> None:
    """The command's one line on Ctrl-C, and exit status 130."""
    print("\nkincas: interrupted", file=sys.stderr)
    raise SystemExit(EXIT_INTERRUPTED)


def interrupted_while_loading() -> None:
    """Exit with the command's one line and status 130 when kincas runs as the command;
    return (the caller re-raises) otherwise."""
    if running_as_command():
        exit_interrupted()
