"""Rough edges a new user hit (issue [12]): user mistakes give one line and exit 2, never a
traceback; sizes that cannot fit are refused up front; messages say what is wrong and only that."""
from __future__ import annotations

import copy

import pytest

import closed_forms as cf
from conftest import EXAMPLES, run_cli, write_scene

FAIRBAIRN = (EXAMPLES / "fairbairn.toml").read_text(encoding="utf-8").split("\n[tolerance]")[0]


def one_line_exit_2(code, err, *words):
    assert code == 2, err
    assert "Traceback" not in err
    lines = [ln for ln in err.strip().splitlines() if ln.strip()]
    assert 1 <= len(lines) <= 2, err  # "error in FILE:" then the problem, or one line
    for w in words:
        assert w.lower() in err.lower(), (w, err)


# --- scenes with nothing to solve ---


@pytest.mark.parametrize("text,words", [
    ("", ["[links]"]),
    ("# only a comment\n", ["[links]"]),
    ('title = "x"\n', ["[links]"]),
    ("[ground]\nA = [0, 0]\n", ["[links]"]),
], ids=["empty", "comment", "title", "ground"])
@pytest.mark.parametrize("command", ["solve", "range"])
def test_a_scene_with_nothing_to_solve_is_refused(capsys, tmp_path, text, words, command):
    code, out, err = run_cli(capsys, command, write_scene(tmp_path, text))
    one_line_exit_2(code, err, *words)


def test_a_file_that_is_not_utf8_is_refused(capsys, tmp_path):
    path = tmp_path / "latin1.toml"
    path.write_bytes('title = "Gelenkgetriebe für Anfänger"\n'.encode("latin-1"))
    code, out, err = run_cli(capsys, "solve", path)
    one_line_exit_2(code, err, "UTF-8")


def test_a_utf8_bom_is_accepted(capsys, tmp_path):
    path = tmp_path / "bom.toml"
    path.write_bytes(b"\xef\xbb\xbf" + FAIRBAIRN.encode("utf-8"))
    code, out, err = run_cli(capsys, "solve", path, "--json")
    assert code == 0, err
    assert out["title"] == "Modified Fairbairn guide"


def test_modes_write_onto_an_existing_file(capsys, tmp_path):
    scene = write_scene(tmp_path, FAIRBAIRN)
    target = tmp_path / "taken"
    target.write_text("not a directory")
    code, out, err = run_cli(capsys, "modes", scene, "--starts", "8", "--write", target)
    one_line_exit_2(code, err, "--write", "taken")


def test_a_negative_seed_is_refused(capsys, tmp_path):
    text = FAIRBAIRN.replace('steps = 361', 'steps = 3') + "\n[tolerance]\nstd = { a1 = 0.1 }\n"
    code, out, err = run_cli(capsys, "tolerance", write_scene(tmp_path, text), "--seed", "-1")
    one_line_exit_2(code, err, "--seed")


def test_ctrl_c_exits_130_in_one_line(capsys, tmp_path, monkeypatch):
    from kincas.cli import app

    def interrupted(args):
        raise KeyboardInterrupt
    monkeypatch.setattr(app, "_solve", interrupted)
    code, out, err = run_cli(capsys, "solve", write_scene(tmp_path, FAIRBAIRN))
    assert code == 130
    assert "Traceback" not in err and len(err.strip().splitlines()) == 1


# --- sizes that cannot fit: refused before any memory is taken ---


@pytest.fixture(autouse=True)
def default_memory_budget(monkeypatch):
    monkeypatch.delenv("KINCAS_MEMORY", raising=False)


def test_the_memory_budget_can_be_raised(monkeypatch):
    from kincas.cli import bounds
    monkeypatch.setenv("KINCAS_MEMORY", "16GB")
    assert bounds.default_budget() == 16e9
    monkeypatch.delenv("KINCAS_MEMORY")
    assert bounds.default_budget() <= 2e9


def test_a_huge_sweep_is_refused_up_front(capsys, tmp_path):
    text = FAIRBAIRN.replace("steps = 361", "steps = 1000000000")
    code, out, err = run_cli(capsys, "solve", write_scene(tmp_path, text))
    one_line_exit_2(code, err, "steps", "GB")


def test_huge_tolerance_samples_are_refused_up_front(capsys, tmp_path):
    text = FAIRBAIRN + "\n[tolerance]\nstd = { a1 = 0.1 }\nsamples = 100000000\n"
    code, out, err = run_cli(capsys, "tolerance", write_scene(tmp_path, text))
    one_line_exit_2(code, err, "samples", "GB")
    code, out, err = run_cli(capsys, "tolerance", write_scene(tmp_path, FAIRBAIRN + "\n[tolerance]\n"
                                                             "std = { a1 = 0.1 }\n"), "--samples", "100000000")
    one_line_exit_2(code, err, "--samples", "GB")


def test_huge_modes_starts_are_refused_up_front(capsys, tmp_path):
    for starts in ("10000000", "10000000000"):  # the typo, and a worse one
        code, out, err = run_cli(capsys, "modes", write_scene(tmp_path, FAIRBAIRN), "--starts", starts)
        one_line_exit_2(code, err, "--starts", "GB")


# --- messages ---


@pytest.mark.parametrize("value", ["true", "nan", "inf", '"long"'])
def test_a_bad_parameter_is_reported_once(capsys, tmp_path, value):
    text = FAIRBAIRN.replace("a1 = 130", f"a1 = {value}")
    code, out, err = run_cli(capsys, "solve", write_scene(tmp_path, text))
    assert code == 2 and "Traceback" not in err
    assert "[parameters] a1" in err
    assert "unknown parameter" not in err, err


def test_an_invalid_name_states_the_rule(capsys, tmp_path):
    text = FAIRBAIRN.replace("B = [330, 0]", 'B = [330, 0]\n"Bé" = [900, 0]')
    code, out, err = run_cli(capsys, "solve", write_scene(tmp_path, text))
    assert code == 2, err
    assert "Bé" in err and "letter" in err and "digits" in err, err


def test_a_ground_point_far_away_is_refused_without_casadi_noise(capfd, tmp_path):
    from kincas.cli import main
    text = FAIRBAIRN.replace("B = [330, 0]", "B = [1e200, 0]")
    code = main(["solve", str(write_scene(tmp_path, text))])
    out, err = capfd.readouterr()
    assert code == 2
    assert "[ground] B" in err and len(err.strip().splitlines()) <= 2, err
    assert "casadi" not in (out + err).lower()


@pytest.mark.parametrize("flag,value,words", [
    ("--pose", "400", ["--pose", "400"]),
    ("--plot", "/nonexistent-dir/x.png", ["--plot", "nonexistent-dir"]),
    ("--csv", "/nonexistent-dir/x.csv", ["--csv", "nonexistent-dir"]),
    ("--plot", "out.nosuchformat", ["--plot", "nosuchformat"]),
])
def test_a_bad_option_is_reported_before_the_solve(capsys, tmp_path, monkeypatch, flag, value, words):
    from kincas.cli import scene as scene_module

    def no_solve(self, **kw):
        raise AssertionError("solved before checking the options")
    monkeypatch.setattr(scene_module.Scene, "run", no_solve)
    monkeypatch.chdir(tmp_path)
    args = [flag, value] + (["--plot", "x.png"] if flag == "--pose" else [])
    code, out, err = run_cli(capsys, "solve", write_scene(tmp_path, FAIRBAIRN), *args)
    one_line_exit_2(code, err, *words)


def test_a_negated_parameter_is_minus_its_value(capsys, tmp_path):
    """`"-d"` where a number is expected means minus parameter d (documented)."""
    scene = copy.deepcopy(cf.load_scene("fourbar_coupler"))
    scene["inputs"] = [{"angle": "crank", "value": 30}]
    plain = run_cli(capsys, "solve", write_scene(tmp_path, scene, "plain.toml"), "--json")[1]
    scene["parameters"]["back"] = -scene["parameters"]["r1"]
    scene["ground"]["O4"] = ["-back", 0]          # minus (-100): the same ground point
    code, negated, err = run_cli(capsys, "solve", write_scene(tmp_path, scene, "neg.toml"), "--json")
    assert code == 0, err
    for k, v in plain["values"].items():
        assert negated["values"][k] == pytest.approx(v, rel=1e-12, abs=1e-12)


def test_the_fairbairn_example_has_a_tolerance_section(capsys):
    code, doc, err = run_cli(capsys, "tolerance", EXAMPLES / "fairbairn.toml", "--samples", "200", "--json")
    assert code == 0, err
    assert set(doc["std"]) == {"a1", "a3", "a62"} and doc["agrees"]


def test_range_of_a_structure_without_inputs_says_so(capsys, tmp_path):
    text = (EXAMPLES / "assur_triad.toml").read_text(encoding="utf-8")
    text = text[:text.index("[[inputs]]")] + text[text.index("\n[guess]"):]
    code, out, err = run_cli(capsys, "range", write_scene(tmp_path, text))
    one_line_exit_2(code, err, "[[inputs]]", "range")


def test_the_size_checks_build_no_model(capsys, tmp_path, monkeypatch):
    """--starts and --samples are checked against the declarations' count of the unknowns
    (Mechanism.structure less the driven angles), the model's count: no CasADi model is built
    to refuse a size."""
    import kincas
    import kincas.core.numeric as numeric
    from kincas.cli.scene import loads
    from kincas.core.caches import Memo
    from kincas.model.mechanism import solved_unknowns
    from conftest import EXAMPLES
    for path in sorted(EXAMPLES.glob("*.toml")):  # the same count as the model's own
        m = loads(path.read_text(encoding="utf-8")).mechanism
        assert solved_unknowns(m) == kincas.model_of(m).nq, path.name
    built = []
    monkeypatch.setattr(numeric, "_CACHE", Memo(bound=64))
    monkeypatch.setattr(numeric.Model, "__init__", lambda self, *a, **k: built.append(1) or 1 / 0)
    text = FAIRBAIRN + "\n[tolerance]\nstd = { a1 = 0.1 }\nsamples = 100000000\n"
    code, out, err = run_cli(capsys, "tolerance", write_scene(tmp_path, text))
    one_line_exit_2(code, err, "samples", "GB")
    assert built == []
