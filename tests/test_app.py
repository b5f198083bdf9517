"""`kincas app`: the JSON API between the live page and its server, through Starlette's test
client (no browser): a change re-solves as `kincas.sweep` does on `with_parameters`, a change
that cannot assemble says so and the next one works, a dragged ground point moves the ground,
a dragged moving point moves the input, the edited scene reads back to the same mechanism, the
server listens on 127.0.0.1 only and stops on Ctrl-C within a second."""
from __future__ import annotations

import math
import re
import signal
import subprocess
import sys
import time
import tomllib
import urllib.request
import warnings
from dataclasses import replace

import numpy as np
import pytest

import kincas
from kincas.cli.scene import load, loads
from kincas.errors import SceneError
from conftest import ROOT

starlette = pytest.importorskip("starlette", reason="kincas[app] is not installed")
pytest.importorskip("httpx", reason="Starlette's test client needs httpx")
with warnings.catch_warnings():  # Starlette 1.x would rather have httpx2; httpx still works
    warnings.simplefilter("ignore")
    from starlette.testclient import TestClient  # noqa: E402

from kincas.cli.serve import HOST, application, bind  # noqa: E402
from kincas.cli.serve_scene import Session  # noqa: E402

FOURBAR = ROOT / "examples" / "fourbar_coupler.toml"


@pytest.fixture
def client():
    sc = load(FOURBAR)
    with TestClient(application(Session(sc, "fourbar.toml", FOURBAR.read_text(encoding="utf-8")))) as c:
        yield c, sc


def column(state, name):
    q = next(q for q in state["plot"]["quantities"] if q["name"] == name)
    return np.array([np.nan if v is None else v for v in q["values"]], float)


def points(state, name):
    d = state["drawing"]
    return np.array(d["xy"], float)[:, d["names"].index(name)]


def test_the_page_and_its_files_are_served_and_reach_nowhere_else(client):
    c, _ = client
    page = c.get("/")
    assert page.status_code == 200 and "text/html" in page.headers["content-type"]
    for f in ("/app.js", "/app.css"):
        r = c.get(f)
        assert r.status_code == 200 and len(r.text) > 500
    text = page.text + c.get("/app.js").text + c.get("/app.css").text
    assert not re.search(r"https?://|//cdn|@import", text), "the page must load nothing from elsewhere"
    assert 'src="app.js"' in page.text and 'href="app.css"' in page.text


def test_a_parameter_change_solves_as_sweep_does_on_with_parameters(client):
    c, sc = client
    r = c.post("/api/change", json={"parameters": {"r2": 35, "px": 20}})
    assert r.status_code == 200, r.text
    st = r.json()
    assert st["message"] == "" and all(st["ok"])
    want = kincas.sweep(sc.mechanism.with_parameters(r2=35, px=20), sc.study.inputs, rates=sc.study.rates,
                        accelerations=sc.study.accelerations, report=sc.quantities)
    for name in ("P.x", "P.vy", "rocker.omega"):
        v = sc.user_values(want)[name]
        np.testing.assert_allclose(column(st, name), v, rtol=1e-9, atol=1e-9 * np.abs(v).max())
    # and independently of kincas: the crank is 35 long, the rocker 80 (loop closure)
    a, o2 = points(st, "A"), points(st, "O2")
    b, o4 = points(st, "B"), points(st, "O4")
    np.testing.assert_allclose(np.hypot(*(a - o2).T), 35, rtol=1e-9)
    np.testing.assert_allclose(np.hypot(*(b - o4).T), 80, rtol=1e-9)
    assert (b[:, 1] > 0).all()  # the open assembly kept: B above the ground line


def test_a_change_that_cannot_assemble_says_so_and_the_next_works(client):
    c, sc = client
    bad = c.post("/api/change", json={"parameters": {"r1": 400}}).json()  # the ground too long
    assert not any(bad["ok"]) and "assemble" in bad["message"]
    good = c.post("/api/change", json={"parameters": {"r1": 105}}).json()
    assert all(good["ok"]) and good["message"] == ""
    b, o4 = points(good, "B"), points(good, "O4")
    np.testing.assert_allclose(o4[:, 0], 105)
    assert (b[:, 1] > 0).all()  # the branch as before the failed change
    want = kincas.sweep(sc.mechanism.with_parameters(r1=105), sc.study.inputs, report=["P.x"])
    np.testing.assert_allclose(column(good, "P.x"), want["P.x"], rtol=1e-9, atol=1e-9)


def test_bad_requests_are_refused_with_a_message(client):
    c, _ = client
    for body in ({"parameters": {"nope": 1}}, {"parameters": {"r2": "x"}}, {"what": 1}):
        r = c.post("/api/change", json=body)
        assert r.status_code == 400 and r.json()["error"], body
    r = c.post("/api/drag", json={"point": "Z", "x": 0, "y": 0})
    assert r.status_code == 400 and "Z" in r.json()["error"]
    assert c.post("/api/change", content=b"{not json").status_code == 400
    assert all(c.post("/api/change", json={"parameters": {"r2": 31}}).json()["ok"])  # still serving


def test_dragging_a_ground_point_moves_the_ground(client):
    c, sc = client
    st = c.post("/api/drag", json={"point": "O2", "x": 5.0, "y": -3.0}).json()  # numbers in the file
    np.testing.assert_allclose(points(st, "O2"), np.tile([5.0, -3.0], (len(st["ok"]), 1)))
    a = points(st, "A")
    np.testing.assert_allclose(np.hypot(*(a - [5.0, -3.0]).T), 30, rtol=1e-9)
    st = c.post("/api/drag", json={"point": "O4", "x": 110.0, "y": 0.0}).json()  # O4 = ["r1", 0]
    assert next(p["value"] for p in st["parameters"] if p["name"] == "r1") == 110.0
    m = replace(sc.mechanism.with_parameters(r1=110.0), ground={"O2": (5.0, -3.0), "O4": ("r1", 0)})
    want = kincas.sweep(m, sc.study.inputs, report=["P.x", "P.y"])
    np.testing.assert_allclose(column(st, "P.y"), want["P.y"], rtol=1e-9, atol=1e-9)


def test_dragging_a_moving_point_moves_the_input(client):
    c, _ = client
    st = c.get("/api/state").json()
    target = points(st, "P")[20] + [0.3, -0.2]  # near the coupler point's 21st pose
    st = c.post("/api/drag", json={"point": "P", "x": target[0], "y": target[1]}).json()
    assert st["pose"] == 20


def test_the_edited_scene_reads_back_to_the_same_mechanism(client):
    c, sc = client
    c.post("/api/change", json={"parameters": {"r3": 95.5}})
    c.post("/api/drag", json={"point": "O2", "x": 2.25, "y": 1.0})
    st = c.get("/api/state").json()
    r = c.get("/api/scene.toml")
    assert r.status_code == 200 and 'filename="fourbar.toml"' in r.headers["content-disposition"]
    assert "r3 = 95.5         # coupler A-B" in r.text and "# Grashof" in r.text  # comments kept
    again = loads(r.text)
    want = replace(sc.mechanism.with_parameters(r3=95.5), ground={"O2": (2.25, 1.0), "O4": ("r1", 0)})
    assert again.mechanism == want
    assert again.study.report == sc.study.report and again.study.title == sc.study.title
    out = again.run()
    np.testing.assert_allclose(again.user_values(out)["P.x"], column(st, "P.x"), rtol=1e-9, atol=1e-9)


VALUE_SCENE = """
title = "crank at one angle"
[parameters]
r = { value = 1, range = [0.5, 1.5] }
[ground]
A = [0, 0]
D = [4, 0]
[links]
crank = { points = ["A", "B"], length = "r" }
coupler = { points = ["B", "C"], length = 3.5 }
rocker = { points = ["D", "C"], length = 3 }
[[inputs]]
angle = "crank"
value = 30
[guess]
C = [3.6, -2.9]
[output]
report = ["C.x", "C.y"]
"""


def closed_form_c(r, theta, below=True):
    """C of the four-bar A(0,0) D(4,0), crank r at theta, coupler 3.5, rocker 3: the two circles'
    intersection (below the line B-D when `below`)."""
    b = np.array([r * math.cos(theta), r * math.sin(theta)])
    d = np.array([4.0, 0.0])
    e = d - b
    L = math.hypot(*e)
    a = (3.5 ** 2 - 3 ** 2 + L ** 2) / (2 * L)
    h = math.sqrt(3.5 ** 2 - a ** 2)
    mid, n = b + a * e / L, np.array([-e[1], e[0]]) / L
    return mid - h * n if below else mid + h * n


def test_a_fixed_input_changes_on_its_branch_and_the_range_is_read():
    sc = loads(VALUE_SCENE)
    assert sc.study.ranges == {"r": (0.5, 1.5)}
    with TestClient(application(Session(sc))) as c:
        st = c.get("/api/state").json()
        assert st["parameters"][0]["lo"] == 0.5 and st["parameters"][0]["hi"] == 1.5
        assert st["inputs"][0]["value"] == 30 and not st["inputs"][0]["swept"]
        st = c.post("/api/change", json={"inputs": {"crank.angle": 250}, "parameters": {"r": 1.2}}).json()
        want = closed_form_c(1.2, math.radians(250))
        np.testing.assert_allclose([column(st, "C.x")[0], column(st, "C.y")[0]], want, atol=1e-9)
        text = c.get("/api/scene.toml").text
    doc = tomllib.loads(text)
    assert doc["inputs"][0]["value"] == 250 and doc["parameters"]["r"] == {"value": 1.2, "range": [0.5, 1.5]}


@pytest.mark.parametrize("entry, words", [
    ("{ value = 1, range = [2, 1] }", ["[parameters] r", "range"]),
    ("{ value = 3, range = [0.5, 1.5] }", ["[parameters] r", "outside"]),
    ("{ range = [0.5, 1.5] }", ["[parameters] r", "value"]),
    ("{ value = 1, span = 2 }", ["[parameters] r", "span"]),
])
def test_a_wrong_parameter_range_is_named(entry, words):
    with pytest.raises(SceneError) as e:
        loads(VALUE_SCENE.replace("{ value = 1, range = [0.5, 1.5] }", entry))
    for w in words:
        assert w in str(e.value)


def test_the_server_binds_127_0_0_1_only():
    sock = bind(0)
    try:
        assert sock.getsockname()[0] == HOST == "127.0.0.1"
    finally:
        sock.close()


def serve(*args):
    proc = subprocess.Popen([sys.executable, "-m", "kincas", "app", *map(str, args), "--no-browser", "--port", "0"],
                            cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    line = proc.stdout.readline()
    m = re.search(r"http://([\d.]+):(\d+)/", line)
    assert m, (line, proc.stderr.read() if proc.poll() is not None else "")
    return proc, m.group(0), m.group(1)


def test_the_command_serves_on_127_0_0_1_and_ctrl_c_stops_it_within_a_second():
    proc, url, host = serve(FOURBAR)
    try:
        assert host == "127.0.0.1"
        with urllib.request.urlopen(url + "api/state", timeout=30) as r:
            assert r.status == 200 and b'"poses":73' in r.read()
        proc.send_signal(signal.SIGINT)
        t = time.perf_counter()
        _, err = proc.communicate(timeout=10)
        waited = time.perf_counter() - t
    finally:
        if proc.poll() is None:
            proc.kill()
    assert waited < 1.5, f"exited {waited:.2f} s after Ctrl-C\n{err}"  # (as tests/test_cli_safety.py: a loaded CI)
    assert proc.returncode == 130 and "interrupted" in err and "Traceback" not in err, err


def test_the_widget_answers_the_page_through_its_messages():
    pytest.importorskip("anywidget", reason="anywidget (kincas[app]) is not installed")
    sc = load(FOURBAR)
    w = kincas.widget(sc)
    assert "export default" in w._esm and "kincasApp" in w._esm and ".kincas-app" in w._css
    sent = []
    w.send = sent.append
    w._answer(w, {"id": 7, "name": "change", "body": {"parameters": {"r2": 35}}})
    assert sent[-1]["id"] == 7 and all(sent[-1]["ok"]["ok"])
    want = kincas.sweep(sc.mechanism.with_parameters(r2=35), sc.study.inputs, report=["P.x"])
    np.testing.assert_allclose(column(sent[-1]["ok"], "P.x"), want["P.x"], rtol=1e-9, atol=1e-9)
    w._answer(w, {"id": 8, "name": "change", "body": {"parameters": {"nope": 1}}})
    assert sent[-1] == {"id": 8, "error": "nothing to change called 'nope'"}
    m = kincas.widget(sc.mechanism).live  # a bare mechanism: its crank turns a full circle
    assert m.state()["poses"] == 361 and all(m.state()["ok"])


def test_instant_centres_meet_kennedys_lines(client):
    """The coupler's instant centre relative to the ground is where the crank's line O2-A meets
    the rocker's line O4-B (Aronhold-Kennedy); the crank's is its pivot."""
    c, _ = client
    st = c.get("/api/state").json()
    o2, a, o4, b = (points(st, p) for p in ("O2", "A", "O4", "B"))
    crank = np.array([[np.nan] * 2 if v is None else v for v in st["centres"]["crank"]], float)
    np.testing.assert_allclose(crank, o2, atol=1e-9)
    for i, ic in enumerate(st["centres"]["coupler"]):
        d1, d2 = a[i] - o2[i], b[i] - o4[i]
        det = d1[0] * -d2[1] + d2[0] * d1[1]
        if abs(det) < 1e-6 * np.hypot(*d1) * np.hypot(*d2):  # parallel: at infinity
            assert ic is None or np.hypot(*(np.array(ic) - b[i])) > 1e3
            continue
        t = ((o4[i] - o2[i])[0] * -d2[1] + d2[0] * (o4[i] - o2[i])[1]) / det
        want = o2[i] + t * d1
        if np.hypot(*(want - b[i])) < 50 * 100:  # drawn only within 50 mechanism sizes
            np.testing.assert_allclose(ic, want, rtol=1e-7, atol=1e-7)


def test_reported_reactions_and_efforts_are_drawn_as_forces():
    sc = load(ROOT / "examples" / "forces_toggle.toml")
    with TestClient(application(Session(sc))) as c:
        st = c.get("/api/state").json()
    f = {x["label"]: x for x in st["drawing"]["forces"]}
    b = f["reaction(B, rocker)"]
    assert st["drawing"]["names"][b["point"]] == "B"
    np.testing.assert_allclose(np.array(b["vectors"])[:, 0], column(st, "reaction(B, rocker).x"))
    np.testing.assert_allclose(f["effort(crank.angle)"]["values"], column(st, "effort(crank.angle)"))
    assert {x["kind"] for x in st["drawing"]["loads"]} == {"torque", "spring"}


def test_a_taken_port_or_a_wrong_scene_is_one_line_and_exit_2(capsys, tmp_path):
    from kincas.cli.app import main
    taken = bind(0)
    try:
        code = main(["app", str(FOURBAR), "--no-browser", "--port", str(taken.getsockname()[1])])
    finally:
        taken.close()
    err = capsys.readouterr().err
    assert code == 2 and "--port" in err and len(err.strip().splitlines()) == 1, err
    bad = tmp_path / "bad.toml"
    bad.write_text("[parameters]\nr = { value = 1, range = [2, 1] }\n[ground]\nA = [0, 0]\n"
                   "[links]\ncrank = { points = [\"A\", \"B\"], length = \"r\" }\n", encoding="utf-8")
    assert main(["app", str(bad), "--no-browser", "--port", "0"]) == 2
    assert "[parameters] r: range" in capsys.readouterr().err


def test_an_edit_that_cannot_be_made_in_place_rewrites_the_whole_scene():
    from kincas.cli.scene_toml import edited
    text = "[parameters]  # sizes\nr = 1  # crank\n[ground]\nA = [\n  0,\n  0,\n]\n"
    old = tomllib.loads(text)
    new = {"parameters": {"r": 2}, "ground": {"A": [0.5, 0]}}
    out = edited(text, old, new)
    assert tomllib.loads(out) == new  # the array over several lines: written afresh
    same = edited(text, old, {"parameters": {"r": 2}, "ground": {"A": [0, 0]}})
    assert same.startswith("[parameters]  # sizes\nr = 2  # crank\n")  # in place, comments kept


def test_weights_and_an_actuators_effort_are_drawn_in_the_app():
    """Gravity weights m g at each cg (views/forces.weights) and a parameter input's effort as
    an arrow along its actuator, equal to the reported effort times the unit vector G -> P."""
    text = (ROOT / "examples" / "actuator_bellcrank.toml").read_text(encoding="utf-8")
    text = text.replace('actuator  = { points = ["G", "P"], length = "stroke" }',
                        'actuator  = { points = ["G", "P"], length = "stroke", mass = 2 }')
    text = text.replace("[parameters]", 'gravity = [0, -9810]\n\n[parameters]')
    text = text.replace('report = ["P.x",', 'report = ["effort(stroke)", "P.x",')
    sc = loads(text)
    with TestClient(application(Session(sc, "a.toml", text))) as c:
        st = c.get("/api/state").json()
    d = st["drawing"]
    (w,) = [x for x in d["loads"] if x["kind"] == "weight"]
    assert w["vector"] == [0, -2 * 9810]
    g, p = points(st, "G"), points(st, "P")
    np.testing.assert_allclose(np.array(w["at"], float), (g + p) / 2, atol=1e-9)  # a bar's middle
    (e,) = [x for x in d["forces"] if x["kind"] == "effort-arrow"]
    assert d["names"][e["point"]] == "P"
    u = (p - g) / np.linalg.norm(p - g, axis=1)[:, None]
    np.testing.assert_allclose(np.array(e["vectors"], float), column(st, "effort(stroke)")[:, None] * u,
                               rtol=1e-9, atol=1e-9)


def test_the_live_page_and_the_html_pages_draw_from_one_shared_script():
    """views/draw.js is the one source of the shapes (pivots, blocks, bodies, joints): inlined
    whole in the offline `--html` pages (planar and spatial: no script is fetched) and served
    ahead of the live page's script; none of the three keeps a copy of its own."""
    import kincas.views.html as html
    import kincas.views.html3d as html3d
    from kincas.views.live import asset
    shared = (ROOT / "kincas" / "views" / "draw.js").read_text(encoding="utf-8")
    sc = load(FOURBAR)
    page = html.html_page(sc.mechanism, sc.run(), sc)
    space = load(ROOT / "examples" / "space_rssr.toml")
    page3 = html.html_page(space.mechanism, space.run(), space)
    for text in (page, page3, asset("app.js")):
        assert text.count(shared) == 1 and "<script src" not in text
    own = [(ROOT / "kincas" / "views" / "live" / "app.js").read_text(encoding="utf-8"),
           html._MECHANISM, html3d.MECHANISM_3D]
    for source in own:  # the pivot's base and the block's rectangle are drawn only in draw.js
        assert "0.7 * h" not in source and "fillRect(-2 * R" not in source
