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
    "range": ("kincas.cli.range", "the input's range of motion, limits, singular poses"),
    "modes": ("kincas.cli.modes", "the assembly modes at the input, as [guess] blocks"),
    "optimize": ("kincas.cli.optimize", "optimise parameters as [optimize] says"),
    "tolerance": ("kincas.cli.tolerance", "spread of the outputs from parameter tolerances"),
    "study": ("kincas.cli.study", "many designs at once, one row each, as [study] says"),
    "cam": ("kincas.cli.cam", "design a disc cam as [cam_design] says"),
    "simulate": ("kincas.cli.simulate", "motion of the free inputs under the loads ([simulate]); --steady"),
    "flywheel": ("kincas.cli.flywheel", "smallest flywheel keeping the speed fluctuation below --fluctuation"),
    "app": ("kincas.cli.serve", "the mechanism in a live page on this machine (kincas[app])"),
}
SOLVE_HELP = "positions, speeds, forces over the scene's inputs"

# An example for each command's help (its last lines); a command without one shows the plain call.
EXAMPLES = {
    "solve": ["kincas solve examples/fourbar_coupler.toml",
              "kincas solve examples/forces_toggle.toml --plot toggle.png --forces --centres",
              "kincas solve examples/slider_crank.toml --html slider.html --svg slider.svg"],
    "range": ["kincas range examples/fourbar_coupler.toml"],
    "modes": ["kincas modes examples/sixbar.toml"],
    "optimize": ["kincas optimize examples/forces_vtwin.toml"],
    "tolerance": ["kincas tolerance examples/fairbairn.toml"],
    "study": ["kincas study examples/study_fourbar.toml --out designs.csv"],
    "simulate": ["kincas simulate examples/simulate_pendulum_fourbar.toml",
                 "kincas simulate examples/simulate_press.toml --steady"],
    "flywheel": ["kincas flywheel examples/simulate_engine.toml --fluctuation 0.02"],
    "app": ["kincas app examples/fourbar_coupler.toml --port 8765"],
    "cam": ["kincas cam my_cam.toml --out profile.toml   (a scene with [cam_design]: docs/scene-format.md)"],
}


class _Help(argparse.RawDescriptionHelpFormatter):
    """Descriptions and examples as written, and each command's one line beside its name
    (argparse measures the commands' names without the indent it prints them with)."""

    def add_argument(self, action):
        super().add_argument(action)
        if isinstance(action, argparse._SubParsersAction) and action.choices:
            longest = max(len(n) for n in action.choices) + self._current_indent + 2 * self._indent_increment
            self._action_max_length = max(self._action_max_length, longest)


def _example(name: str) -> str:
    lines = EXAMPLES.get(name) or [f"kincas {name} SCENE.toml"]
    return "example:\n" + "\n".join("  " + ln for ln in lines)


def _parser(argv: list[str] | None = None) -> argparse.ArgumentParser:
    def raw(prog):  # descriptions and examples as written; a command's help beside its name
        return _Help(prog, max_help_position=28)
    ap = argparse.ArgumentParser(prog="kincas", description="Kinematics and motion of closed-chain mechanisms, planar and spatial.",
                                 formatter_class=raw,
                                 epilog="examples:\n  kincas solve examples/fourbar_coupler.toml --plot fourbar.png\n"
                                        "  kincas solve --help       (each command's options)")
    ap.add_argument("--version", action="store_true", help="print the version and exit")
    sub = ap.add_subparsers(dest="command", metavar="COMMAND")
    s = sub.add_parser("solve", help=SOLVE_HELP, description=SOLVE_HELP, epilog=_example("solve"),
                       formatter_class=raw)
    _solve_arguments(s)
    s.set_defaults(run=lambda args: _solve(args))  # looked up when run (tests replace it)
    chosen = next((a for a in (argv or []) if not a.startswith("-")), None)
    for name, (module, text) in COMMANDS.items():
        c = sub.add_parser(name, help=text, description=text, epilog=_example(name), formatter_class=raw)
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
    starts = getattr(args, "starts", None)
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
            from .tolerance import draws_option
            flag, n = draws_option(args, note=False)
            field, n = (flag, n) if n else ("[tolerance] samples", t.get("samples"))
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
