"""The command line: `kincas solve SCENE.toml [--json]`.

Exit status: 0 when every pose was solved, 3 when some were not, 2 when the scene itself is
wrong (with one message on standard error naming the section and the field, no traceback),
or an output cannot be written (a file, or standard output on a full device), 130 on Ctrl-C.

>>> main(["--version"])
kincas 0.1.0
0
"""
from __future__ import annotations

import argparse
import importlib
import sys


from .. import __version__
from ..errors import KincasError, OutputError
from .common import (EXIT_INTERRUPTED, EXIT_OK, EXIT_SCENE, EXIT_UNSOLVED,  # noqa: F401
                     _list, _unit, progress_for)
from .common import _param_unit  # noqa: F401
from .solve import cli_arguments as _solve_arguments, cli_run as _solve, rate_line  # noqa: F401


# Further commands live in their own modules: each defines `cli_arguments(parser)` and
# `cli_run(args) -> exit status`, and is imported only when it exists.
COMMANDS = {
    "range": ("kincas.cli.range", "range of motion of the input, its limits and singular positions"),
    "modes": ("kincas.cli.modes", "the distinct assembly modes at the scene's input, as [guess] blocks"),
    "optimize": ("kincas.cli.optimize", "optimise parameters as the scene's [optimize] section says"),
    "tolerance": ("kincas.cli.tolerance", "first-order and Monte-Carlo spread of outputs from parameter tolerances"),
    "study": ("kincas.cli.study", "many designs at once: the scene's [study] section, one row per design"),
    "cam": ("kincas.cli.cam", "design a disc cam from the scene's [cam_design] section (profile, pressure angle, curvature)"),
    "simulate": ("kincas.cli.simulate", "motion of the free inputs under the loads over time ([simulate]); --steady: periodic steady state"),
    "flywheel": ("kincas.cli.flywheel", "smallest flywheel inertia keeping the steady speed fluctuation below --fluctuation"),
}


def _parser(argv: list[str] | None = None) -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(prog="kincas", description="Kinematics of planar closed-chain mechanisms.")
    ap.add_argument("--version", action="store_true", help="print the version and exit")
    sub = ap.add_subparsers(dest="command")
    s = sub.add_parser("solve", help="solve a scene: positions, velocities, accelerations over its inputs")
    _solve_arguments(s)
    s.set_defaults(run=lambda args: _solve(args))  # looked up when run (tests replace it)
    chosen = next((a for a in (argv or []) if not a.startswith("-")), None)
    for name, (module, text) in COMMANDS.items():
        c = sub.add_parser(name, help=text)
        if name != chosen:  # only the command being run is imported
            continue
        mod = importlib.import_module(module)
        mod.cli_arguments(c)
        c.set_defaults(run=mod.cli_run)
    return ap


def main(argv: list[str] | None = None) -> int:
    """Run the command line; returns the exit status."""
    argv = sys.argv[1:] if argv is None else list(argv)
    try:
        ap = _parser(argv)  # imports the command's module: Ctrl-C may come while it does
    except KeyboardInterrupt:
        print("\nkincas: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    args = ap.parse_args(argv)
    if args.version:
        print(f"kincas {__version__}")
        return EXIT_OK
    if args.command is None:
        ap.print_help()
        return EXIT_SCENE
    try:
        _check_args(args)
        status = args.run(args)
        sys.stdout.flush()  # a full device or a closed pipe shows here, not at the exit
        return status
    except KeyboardInterrupt:  # Ctrl-C: the user knows why; one line, the shell's usual 130
        print("\nkincas: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    except BrokenPipeError:  # `kincas solve ... | head`: the reader left, nothing is wrong
        _drop_stdout()
        return EXIT_OK
    except OutputError as e:  # a file or option that cannot be honoured: one line
        print(f"kincas: {e}", file=sys.stderr)
        return EXIT_SCENE
    except KincasError as e:
        print(f"kincas: error in {getattr(args, 'scene', 'scene')}:\n{e}", file=sys.stderr)
        return EXIT_SCENE
    except OSError as e:  # files are written as OutputError naming them: this is the output
        _drop_stdout()
        where = f"cannot write {e.filename}" if e.filename else "cannot write to standard output"
        print(f"kincas: {where}: {e.strerror or e}", file=sys.stderr)
        return EXIT_SCENE


def _drop_stdout() -> None:
    """Standard output to /dev/null from here on: what is still buffered in it would fail
    again at the exit, with Python's "Exception ignored ... flush" on standard error."""
    import os
    try:
        fd = sys.stdout.fileno()
        null = os.open(os.devnull, os.O_WRONLY)
        os.dup2(null, fd)
        os.close(null)
    except (AttributeError, OSError, ValueError):  # not a real file (tests capture it)
        pass


def _check_args(args) -> None:
    """Options every command shares, checked before any work: a seed is >= 0, --write names a
    directory, and --starts / --samples fit in memory (a typo must not take the machine)."""
    from pathlib import Path
    from . import bounds
    _not_the_scene(args)
    seed = getattr(args, "seed", None)
    if seed is not None and seed < 0:
        raise OutputError(f"--seed: expected a whole number >= 0, got {seed}")
    write = getattr(args, "write", None)
    if write and Path(write).exists() and not Path(write).is_dir():
        raise OutputError(f"--write: {write} exists and is not a directory (--write names a directory)")
    starts, samples = getattr(args, "starts", None), getattr(args, "samples", None)
    if not (starts or args.command in ("tolerance", "range")):
        return
    from ..model.mechanism import solved_unknowns
    from .scene import load
    sc = load(args.scene)
    if args.command == "range" and not sc.study.inputs:
        raise OutputError("[[inputs]]: none declared, so there is no range of motion to find "
                          "(kincas range ranges an input; kincas solve solves a structure)")
    # the declarations' count of the unknowns, so that a size check builds no model
    nq, nrep = solved_unknowns(sc.mechanism), len(sc.quantities)
    try:
        if starts:
            bounds.check("--starts", starts, bounds.per_sample(nq, 0, 0))
        if args.command == "tolerance":
            t = sc.study.raw.get("tolerance", {})
            field, n = ("--samples", samples) if samples else ("[tolerance] samples", t.get("samples"))
            if isinstance(n, int) and not isinstance(n, bool) and n > 0:
                std = t.get("std", {})
                poses = max((len(v) for v in sc.study.inputs.values()), default=1)
                from ..analysis.executor import default_workers
                need = bounds.tolerance_bytes(n, poses, nq, nrep, len(std) if isinstance(std, dict) else 1,
                                              default_workers())
                bounds.check_total(f"{field}: {n} (x {poses} poses)", need, "use fewer")
    except ValueError as e:
        raise OutputError(str(e)) from None


# options that name a file the command writes, as the user spells them
OUTPUT_OPTIONS = {"csv": "--csv", "plot": "--plot", "animate": "--animate",
                  "plot_quantities": "--plot-quantities", "html": "--html", "svg": "--svg",
                  "dxf": "--dxf", "out": "--out"}


def _not_the_scene(args) -> None:
    """No output may be the scene file itself (by any spelling or link): it would be lost."""
    from ..views.atomic import same_file
    scene = getattr(args, "scene", None)
    for attr, flag in OUTPUT_OPTIONS.items():
        path = getattr(args, attr, None)
        if scene and path and same_file(path, scene):
            raise OutputError(f"{flag}: {path} is the scene file itself; it would be overwritten "
                              f"(name another file)")
