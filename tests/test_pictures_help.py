"""The command line as a new user reads it: `kincas --help` lists each command with a one-line
description, each command's help ends with an example, and `kincas optimize` labels a bound
on a force in force units (issue [19])."""
from __future__ import annotations

import pytest

from kincas.cli.app import COMMANDS, main


def _help(capsys, *argv) -> str:
    with pytest.raises(SystemExit) as e:
        main([*argv, "--help"])
    assert e.value.code == 0
    return capsys.readouterr().out


def test_the_main_help_lists_every_command_in_one_line(capsys):
    out = _help(capsys)
    for name in COMMANDS:
        lines = [ln for ln in out.splitlines() if ln.strip().startswith(name + " ")]
        assert lines, f"{name} missing from kincas --help:\n{out}"
        words = lines[0].split(None, 1)
        assert len(words) == 2 and len(words[1]) > 15, lines[0]  # a description beside it
    assert "example" in out.lower() and "kincas solve" in out


@pytest.mark.parametrize("command", sorted(COMMANDS))
def test_each_command_has_a_description_and_an_example(capsys, command):
    out = _help(capsys, command)
    tail = out[out.rindex("example:"):]
    assert f"kincas {command} " in tail, out
    head = out.split("\n\n")[1] if out.count("\n\n") else ""
    assert head.strip() and len(head.strip().splitlines()) <= 3, out[:400]


def test_a_force_bound_is_labelled_in_force_units():
    from kincas.cli.optimize import _objective_unit, _optimized_unit
    from kincas.cli.scene import load
    sc = load("examples/forces_vtwin.toml")  # units: force = "N"
    # peak bounds hypot(shaking.x, shaking.y): a force; cw is a length along the crank
    assert _optimized_unit(sc, "peak") == "N"
    assert _optimized_unit(sc, "cw") == "mm"
    assert _objective_unit(sc) == "N"  # minimize = "peak"


def test_a_mass_parameter_is_labelled_in_mass_units():
    from kincas.cli.common import _param_unit
    from kincas.cli.scene import loads
    text = open("examples/forces_vtwin.toml").read().replace(
        'time = "s" }', 'time = "s", force = "N", mass = "t" }').replace("[parameters]", "[parameters]\nmc = 0.003")
    text = text.replace("mass = 0.003", 'mass = "mc"')
    sc = loads(text)
    assert _param_unit(sc, "mc") == "t"
    assert _param_unit(sc, "r") == "mm"


def test_every_help_example_parses_with_its_commands_options():
    """Each command's help example is a command line its parser accepts (the study example
    once gave --csv, which `kincas study` does not have) and names a shipped example file."""
    import shlex
    from kincas.cli.app import EXAMPLES, _parser
    from conftest import ROOT
    for name, lines in EXAMPLES.items():
        for line in lines:
            argv = shlex.split(line.split("   (")[0])[1:]
            ap = _parser(argv)
            ap.parse_args(argv)  # argparse exits (SystemExit) on an unknown option
            scene = next(a for a in argv[1:] if a.endswith(".toml"))
            assert scene.startswith("my_") or (ROOT / scene).exists(), (name, line)
