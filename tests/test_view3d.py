"""Pictures of spatial mechanisms (issue [16]): the projections (iso, xy, yz, zx) checked
against the textbook isometric construction, and every picture (SVG, matplotlib, GIF, DXF,
HTML) of a spatial sweep built by hand: a fake mechanism whose `poses.geometry` gives world
positions N x K x 3 (the interface the spatial core fills), over a real planar sweep for
the inputs and statuses. The HTML page's script runs under node with a stub DOM (the mouse
turns the view) and in headless Chromium (it draws the points where the camera says)."""
from __future__ import annotations

import json
import math
import re
import shutil
import subprocess
import xml.etree.ElementTree as ET
from types import SimpleNamespace

import numpy as np
import pytest

import kincas
import kincas.views.animation, kincas.views.dxf, kincas.views.html, kincas.views.plot, kincas.views.svg  # noqa: E401,F401
from kincas.views import poses  # (imported before `spatial` patches poses.geometry: none keeps the fake)
from kincas.views.poses import Geometry
from kincas.views.projection import axes, check_view, in_plane, project, project_points

from conftest import run_cli

SVG = "{http://www.w3.org/2000/svg}"
K = math.sqrt(2 / 3)  # isometric foreshortening of every axis


def iso_textbook(p):
    """The isometric drawing of p: the three axes drawn 120 degrees apart, each shortened by
    sqrt(2/3): z straight up, x towards 210 degrees, y towards 330 degrees."""
    x, y, z = p
    ang = {0: math.radians(210), 1: math.radians(330), 2: math.radians(90)}
    return (K * sum(c * math.cos(ang[j]) for j, c in enumerate((x, y, z))),
            K * sum(c * math.sin(ang[j]) for j, c in enumerate((x, y, z))))


def drawn_in(p, view):
    """p drawn in an axis view by hand: the two coordinates the view shows."""
    x, y, z = p
    return {"xy": (x, y), "yz": (y, z), "zx": (z, x)}[view] if view != "iso" else iso_textbook(p)


# --- the projections ---

@pytest.mark.parametrize("view", ["iso", "xy", "yz", "zx"])
def test_projection_against_hand_coordinates(view):
    rng = np.random.default_rng(3)
    pts = rng.normal(size=(20, 3)) * [50, 80, 30]
    xy, depth = project_points(pts, view)
    assert xy == pytest.approx(np.array([drawn_in(p, view) for p in pts]), abs=1e-12)
    # depth: farther from the viewer, who looks from +toward; a step towards the viewer lowers it
    toward = {"iso": np.ones(3) / math.sqrt(3), "xy": [0, 0, 1], "yz": [1, 0, 0], "zx": [0, 1, 0]}[view]
    assert depth == pytest.approx(-(pts @ np.asarray(toward, float)), abs=1e-12)
    # orthographic: a segment parallel to the drawing plane keeps its length
    a = axes(view)
    seg = np.array([np.zeros(3), 7 * a[0] + 3 * a[1]])
    assert np.linalg.norm(np.diff(project_points(seg, view)[0], axis=0)) == pytest.approx(math.sqrt(58))


def test_iso_unit_axes_are_120_degrees_apart_and_nan_stays_nan():
    xy, _ = project_points(np.eye(3), "iso")
    assert np.hypot(*xy.T) == pytest.approx([K] * 3)
    angles = sorted(math.degrees(math.atan2(v[1], v[0])) % 360 for v in xy)
    assert angles == pytest.approx([90, 210, 330])
    xy, depth = project_points(np.array([[np.nan, 0, 0]]), "iso")
    assert np.isnan(xy).all() and np.isnan(depth).all()


def test_views_are_checked():
    assert check_view(None, True) == "iso" and check_view(None, False) is None
    with pytest.raises(ValueError, match="planar scene"):
        check_view("iso", False)
    with pytest.raises(ValueError, match="not a view"):
        check_view("top", True)


def test_a_slide_line_projects_onto_its_drawn_point():
    t = np.array([[0.0, -50, 10], [5, 5, 5], [1, 2, 3]])
    d = np.array([[1.0, 2, 2], [0, 0, 1], [1, 1, 1]]) / np.array([[3], [1], [math.sqrt(3)]])
    s = np.array([20.0, -3, 4])
    pt = t + s[:, None] * d
    g = Geometry(["P"], pt[:, None, :], {"sl": (t, d, s)}, np.ones(3, bool))
    p = project(g, "iso")
    t2, d2, s2 = p.slides["sl"]
    # rows 0 and 1: drawn t + s' d' is the drawn point, d' a unit vector
    assert (t2 + s2[:, None] * d2)[:2] == pytest.approx(p.xy[:2, 0], abs=1e-12)
    assert np.hypot(*d2[:2].T) == pytest.approx([1, 1])
    # row 2: the line (1, 1, 1) is seen end on in the isometric view: no direction to draw
    assert np.isnan(d2[2]).all() and np.isnan(s2[2])
    assert p.depth.shape == (3, 1) and p.world is g.xy and p.view == "iso"


def test_a_body_outline_is_chosen_in_its_own_plane():
    # a square tilted in space, its points given out of order: the outline goes round it
    e1, e2 = np.array([1.0, 1, 0]) / math.sqrt(2), np.array([0, 0, 1.0])
    sq = np.array([[0, 0], [1, 1], [1, 0], [0, 1]], float) * 10
    pts = sq @ np.array([e1, e2]) + [3, 4, 5]
    flat = in_plane(pts)
    d = np.linalg.norm(flat[:, None] - flat[None], axis=2)
    assert d == pytest.approx(np.linalg.norm(sq[:, None] - sq[None], axis=2), abs=1e-12)


# --- a spatial mechanism, by hand ---

N = 13
T = np.linspace(0, 2 * np.pi, N)
D_PT = np.array([120.0, 40, 30])
GUIDE_T, GUIDE_D = np.array([0.0, -50, 10]), np.array([1.0, 2, 2]) / 3


def world():
    """RSSR-like positions: crank A-B about z, rocker D-C-E (a triangle in the plane x = 120)
    about x, a point F on a ground line (the slide 'pad'), pushrod B-F."""
    phi = 1 + 0.3 * np.sin(T)
    A = np.zeros((N, 3))
    Dp = np.tile(D_PT, (N, 1))
    B = np.stack([25 * np.cos(T), 25 * np.sin(T), np.zeros(N)], axis=1)
    C = D_PT + 60 * np.stack([np.zeros(N), np.cos(phi), np.sin(phi)], axis=1)
    E = D_PT + 30 * np.stack([np.zeros(N), -np.sin(phi), np.cos(phi)], axis=1)
    s = 40 + 20 * np.sin(T)
    F = GUIDE_T + s[:, None] * GUIDE_D
    return ["A", "D", "B", "C", "E", "F"], np.stack([A, Dp, B, C, E, F], axis=1), s


def fake_geometry(m, sweep):
    names, xyz, s = world()
    slides = {"pad": (np.tile(GUIDE_T, (N, 1)), np.tile(GUIDE_D, (N, 1)), s),
              "floor": (np.zeros((N, 3)), np.tile([0.0, 0, 1], (N, 1)), np.zeros(N))}  # a plane: its normal
    return Geometry(names, xyz, slides, np.ones(N, bool))


LINKS = {"crank": ("A", "B"), "coupler": ("B", "C"), "rocker": ("D", "C", "E"), "pushrod": ("B", "F")}


@pytest.fixture()
def spatial(monkeypatch):
    """(fake spatial mechanism, a real sweep of N poses): poses.geometry gives world()."""
    monkeypatch.setattr(poses, "geometry", fake_geometry)
    m = SimpleNamespace(
        space="3d", ground_points=("A", "D"), moving_points=("B", "C", "E", "F"),
        bodies=[SimpleNamespace(name=k, point_names=v) for k, v in LINKS.items()],  # as SpatialMechanism
        slides=[SimpleNamespace(name="pad", point="F", along="ground"),
                SimpleNamespace(name="floor", point="E", along="ground", on_line=False)],  # on a plane: not drawn
        inputs=[SimpleNamespace(kind="joint", target="A", key="A.angle")],
        size=lambda: 150.0, parameters=[], gears=[], racks=[], cams=[])
    planar = kincas.Mechanism(ground={"O": (0, 0)}, links=[kincas.Link.bar("crank", "O", "P", 1)],
                              inputs=[kincas.Input.angle("crank")])
    return m, kincas.sweep(planar, {"crank.angle": T}, report=["P.x"])


def world_paths():
    names, xyz, _ = world()
    return {p: xyz[:, names.index(p)] for p in ("B", "C", "E", "F")}


@pytest.mark.parametrize("view", [None, "iso", "yz", "zx"])
def test_svg_of_a_spatial_mechanism_has_its_projected_points(spatial, view):
    from kincas.views.svg import svg_text
    m, sw = spatial
    pose = 4
    root = ET.fromstring(svg_text(m, sw, pose, view=view, dense=world_paths()))
    assert root.get("data-view") == (view or "iso")
    names, xyz, _ = world()
    circles = {c.get("data-point"): (float(c.get("cx")), float(c.get("cy"))) for c in root.iter(SVG + "circle")}
    for k, p in enumerate(names):
        assert circles[p] == pytest.approx(drawn_in(xyz[pose, k], view or "iso"), abs=1e-7), p
    # the rocker is a triangle, its corners the drawn D, C, E; the bars end at their points
    tri = next(e for e in root.iter(SVG + "polygon") if e.get("data-link") == "rocker")
    corners = {tuple(round(float(v), 6) for v in q.split(",")) for q in tri.get("points").split()}
    assert corners == {tuple(round(v, 6) for v in circles[p]) for p in "DCE"}
    # the path of C (a circle about D's axis), drawn as the view shows it
    path_c = [e for e in root.iter(SVG + "polyline") if e.get("data-path") == "C"]
    pts = np.array([[float(v) for v in q.split(",")] for e in path_c for q in e.get("points").split()])
    assert pts == pytest.approx(np.array([drawn_in(q, view or "iso") for q in world_paths()["C"]]), abs=1e-7)
    # bodies farthest first: the order of the data-link elements follows the mean depth
    order = [e.get("data-link") for e in root.iter() if e.get("data-link")]
    depth = {k: np.mean([project_points(xyz[pose, names.index(p)], view or "iso")[1] for p in v])
             for k, v in LINKS.items()}
    assert order == sorted(LINKS, key=lambda k: -depth[k])
    assert {e.get("data-axis") for e in root.iter(SVG + "line") if e.get("data-axis")} == {"x", "y", "z"}


def test_matplotlib_drawing_and_animation_of_a_spatial_mechanism(spatial, tmp_path):
    from matplotlib.figure import Figure
    from kincas.views.animation import animate
    from kincas.views.plot import draw
    m, sw = spatial
    ax = draw(m, sw, 2, ax=Figure().subplots(), path_xy=world_paths(), view="yz", units="mm")
    names, xyz, _ = world()
    crank = next(line for line in ax.get_lines() if line.get_label() == "crank")
    assert np.column_stack(crank.get_data()) == pytest.approx(xyz[2, [0, 2]][:, 1:], abs=1e-12)
    assert ax.get_xlabel() == "y [mm]" and ax.get_ylabel() == "z [mm]"
    ax = draw(m, sw, 2, ax=Figure().subplots(), path_xy=world_paths())  # iso by default
    crank = next(line for line in ax.get_lines() if line.get_label() == "crank")
    assert np.column_stack(crank.get_data()) == pytest.approx(np.array([iso_textbook(p) for p in xyz[2, [0, 2]]]))
    with pytest.raises(ValueError, match="not a view"):
        draw(m, sw, 2, ax=Figure().subplots(), path_xy=world_paths(), view="top")
    assert animate(m, sw, tmp_path / "s.gif", frames=3, size=(2, 1.5), dpi=40, path_xy=world_paths()) == 3


def test_dxf_of_a_spatial_mechanism_is_in_space(spatial, tmp_path):
    ezdxf = pytest.importorskip("ezdxf")
    from kincas.views.dxf import write_dxf
    m, sw = spatial
    pose = 5
    write_dxf(tmp_path / "s.dxf", m, sw, pose, dense=world_paths(), units="mm")
    names, xyz, s = world()
    at = lambda p: xyz[pose, names.index(p)]
    msp = ezdxf.readfile(tmp_path / "s.dxf").modelspace()
    crank, = msp.query('LINE[layer=="crank"]')
    assert tuple(crank.dxf.start) == pytest.approx(at("A")) and tuple(crank.dxf.end) == pytest.approx(at("B"))
    rocker, = msp.query('POLYLINE[layer=="rocker"]')
    assert rocker.is_3d_polyline and rocker.is_closed
    corners = np.array([tuple(v.dxf.location) for v in rocker.vertices])
    assert sorted(map(tuple, corners.round(9))) == sorted(tuple(at(p).round(9)) for p in "DCE")
    paths = msp.query('POLYLINE[layer=="paths"]')
    got = np.array([tuple(v.dxf.location) for e in paths for v in e.vertices])
    want = np.concatenate(list(world_paths().values()))
    assert got == pytest.approx(want, abs=1e-9) and np.ptp(got[:, 2]) > 50  # heights vary: truly 3D
    guide, = msp.query('LINE[layer=="ground"]')
    ends = np.array([tuple(guide.dxf.start), tuple(guide.dxf.end)]) - GUIDE_T
    assert np.cross(ends, GUIDE_D) == pytest.approx(np.zeros((2, 3)), abs=1e-9)  # on the guide's line
    block, = msp.query('POLYLINE[layer=="slides"]')
    mid = np.mean([tuple(v.dxf.location) for v in block.vertices], axis=0)
    assert mid == pytest.approx(at("F"))
    # a circle round each point of each body and each ground pivot, at its height
    zs = sorted(round(c.dxf.center[2], 9) for c in msp.query("CIRCLE"))
    assert zs == sorted(round(at(p)[2], 9) for p in "".join("".join(b) for b in LINKS.values()) + "AD")


def test_spatial_pictures_keep_the_true_scale_and_names_and_refuse_the_planar_overlay(spatial, tmp_path):
    """The pictures branch's features on a spatial picture: the SVG's true-scale size beside
    its view, every point named; DXF names at the points in space; forces and instant centres
    (planar quantities) refused by the library and, in one line, by the command line."""
    ezdxf = pytest.importorskip("ezdxf")
    from kincas.cli.outputs import check_outputs
    from kincas.errors import OutputError
    from kincas.views.dxf import write_dxf
    from kincas.views.svg import svg_text
    m, sw = spatial
    pose = 4
    names, xyz, _ = world()
    root = ET.fromstring(svg_text(m, sw, pose, view="zx", dense=world_paths(), units="mm"))
    vb = [float(v) for v in root.get("viewBox").split()]
    assert root.get("data-view") == "zx"
    for attr, size in (("width", vb[2]), ("height", vb[3])):  # 1 mm of the scene is 1 mm of the file
        assert root.get(attr).endswith("mm") and float(root.get(attr)[:-2]) == pytest.approx(size, rel=1e-5)
    labels = next(g for g in root.iter(SVG + "g") if g.get("id") == "labels")
    assert sorted(t.text for t in labels) == sorted(names)
    for t in labels:  # each name near its drawn point (within a few point radii of the picture)
        u, v = drawn_in(xyz[pose, names.index(t.text)], "zx")
        assert math.hypot(float(t.get("x")) - u, -float(t.get("y")) - v) < 0.2 * 150
    write_dxf(tmp_path / "s.dxf", m, sw, pose, dense=world_paths(), units="mm")
    texts = {e.dxf.text: tuple(e.dxf.insert) for e in ezdxf.readfile(tmp_path / "s.dxf").modelspace()
             .query('TEXT[layer=="labels"]')}
    assert set(texts) == set(names)
    for p in names:
        assert texts[p] == pytest.approx(xyz[pose, names.index(p)], abs=1e-9)
    for flag in ("forces", "centres"):
        with pytest.raises(ValueError, match="spatial"):
            svg_text(m, sw, pose, dense=world_paths(), **{flag: True})
        args = SimpleNamespace(svg=str(tmp_path / "a.svg"), view=None, evolute=None, centrodes=None, **{flag: True})
        with pytest.raises(OutputError, match="--forces, --centres.*spatial") as e:
            check_outputs(args, m, N)
        assert len(str(e.value).splitlines()) == 1


def test_dxf_text_carries_the_z_group_codes(spatial, tmp_path):
    """Independently of ezdxf's reader: the file's POLYLINE vertices have z (group 30)."""
    pytest.importorskip("ezdxf")
    from kincas.views.dxf import write_dxf
    m, sw = spatial
    write_dxf(tmp_path / "s.dxf", m, sw, 0, dense=world_paths())
    lines = (tmp_path / "s.dxf").read_text().splitlines()
    pairs = list(zip(lines[::2], lines[1::2]))
    vertex_z = []
    for k, (code, value) in enumerate(pairs):
        if code.strip() == "0" and value == "VERTEX":
            group = dict((c.strip(), v) for c, v in pairs[k + 1:k + 30])
            vertex_z.append(float(group["30"]))
    names, xyz, _ = world()
    assert len(vertex_z) > N and max(vertex_z) == pytest.approx(xyz[:, names.index("C"), 2].max())


# --- the HTML page ---

NODE = shutil.which("node")


@pytest.fixture()
def page(spatial):
    from kincas.views.html import html_page
    m, sw = spatial
    return html_page(m, sw, dense=world_paths())


def test_the_spatial_page_is_offline_and_carries_the_world(page):
    assert "<script src" not in page and "<link" not in page
    assert not re.search(r"https?://", page) and not re.search(r"//[a-z0-9.-]+\.[a-z]{2,}/", page)
    data = json.loads(re.search(r"const D = (\{.*?\});\n", page, re.S).group(1))
    names, xyz, _ = world()
    assert np.array(data["xy"], float) == pytest.approx(xyz, abs=1e-6)
    assert np.array(data["camera"]) == pytest.approx(axes("iso")) and data["up"] == 2
    assert "pointermove" in page and "wheel" in page


def _script(page):
    return re.search(r"<script>\n(.*)</script>", page, re.S).group(1)


STUB_DOM = r"""
const handlers = {}, elements = {};
function element(id) {
  if (!elements[id]) elements[id] = {
    id, width: 640, height: 480, clientWidth: 640, clientHeight: 480, style: {}, dataset: {}, textContent: "",
    value: "0", max: "0", getBoundingClientRect: () => ({ left: 0, top: 0 }),
    getContext: () => new Proxy({}, { get: (t, k) => (k in t ? t[k] : () => {}), set: (t, k, v) => { t[k] = v; return true; } }),
    addEventListener: (ev, f) => { handlers[ev] = f; }, setPointerCapture: () => {},
    insertBefore: () => {}, appendChild: () => {}, set onclick(f) { handlers["click:" + id] = f; }, set oninput(f) {},
  };
  return elements[id];
}
global.document = { getElementById: element, body: element("body"), title: "",
                    createElement: () => element("b" + Object.keys(elements).length) };
global.window = { addEventListener: () => {}, innerWidth: 1000, innerHeight: 700, scrollX: 0, scrollY: 0 };
global.location = { hash: "#pose=3&view=yz" };
"""

DRIVE = r"""
const out = { start: JSON.parse(document.body.dataset.camera), pose: document.body.dataset.pose };
const ev = (x, y, shift) => ({ clientX: x, clientY: y, shiftKey: !!shift, pointerId: 1, preventDefault() {} });
handlers.pointerdown(ev(100, 100)); handlers.pointermove(ev(160, 130)); handlers.pointerup(ev(160, 130));
out.turned = JSON.parse(document.body.dataset.camera);
const s0 = +document.body.dataset.transform.split(" ")[0];
handlers.wheel({ deltaY: -300, preventDefault() {} });
out.zoom = +document.body.dataset.transform.split(" ")[0] / s0;
handlers.dblclick();
out.back = JSON.parse(document.body.dataset.camera);
console.log(JSON.stringify(out));
"""


@pytest.mark.skipif(NODE is None, reason="node is not installed")
def test_the_page_script_parses_and_turns_with_the_mouse(page, tmp_path):
    js = tmp_path / "page.js"
    js.write_text(_script(page))
    check = subprocess.run([NODE, "--check", str(js)], capture_output=True, text=True, timeout=60)
    assert check.returncode == 0, check.stderr
    run = tmp_path / "run.js"
    run.write_text(STUB_DOM + _script(page) + DRIVE)
    res = subprocess.run([NODE, str(run)], capture_output=True, text=True, timeout=60)
    assert res.returncode == 0, res.stderr
    out = json.loads(res.stdout.strip().splitlines()[-1])
    assert str(out["pose"]) == "3" and np.array(out["start"]) == pytest.approx(axes("yz"))  # from #view=yz
    c = np.array(out["turned"])
    assert not np.allclose(c, axes("yz"), atol=1e-3)  # the drag turned it
    assert c @ c.T == pytest.approx(np.eye(3), abs=1e-12) and np.linalg.det(c) == pytest.approx(1)
    # sideways, it turned about z (yz's upward axis) and tilted about the screen's horizontal: the drawing's
    # right axis stays horizontal (z stays upright on the screen, never leaning sideways)
    assert abs(c[0, 2]) < 1e-12
    assert out["zoom"] == pytest.approx(math.exp(0.0015 * 300))
    assert np.array(out["back"]) == pytest.approx(axes("iso"))  # double-click: the view it opened in


BROWSER = next((shutil.which(b) for b in ("chromium", "chromium-browser", "google-chrome") if shutil.which(b)), None)


@pytest.mark.skipif(BROWSER is None, reason="no headless Chromium on this machine")
def test_the_page_draws_in_a_browser_where_the_camera_says(page, tmp_path, view="zx"):
    from test_html import _driver, _shot
    path = tmp_path / "s.html"
    path.write_text(page, encoding="utf-8")
    driver = _driver()  # one window for the transform and the screenshot (the page fills the window)
    try:
        errors, shown, (s, ox, oy), shot = _shot(driver, path.as_uri() + f"#pose=4&view={view}")
        camera = driver.find_element("tag name", "body").get_attribute("data-camera")
    finally:
        driver.quit()
    assert errors.strip() == "" and shown == "4"
    cam = np.array(json.loads(camera))
    assert cam == pytest.approx(axes(view), abs=1e-12)
    img = np.asarray(shot).astype(int)
    names, xyz, _ = world()
    # the middle of the crank A-B at pose 4, where the projection puts it: the crank's colour
    mid = 0.5 * (xyz[4, 0] + xyz[4, 2])
    u, v = drawn_in(mid, view)
    x, y = ox + s * u, oy - s * v
    patch = img[int(y) - 1:int(y) + 2, int(x) - 1:int(x) + 2].reshape(-1, 3)
    assert (np.abs(patch - [0x1F, 0x77, 0xB4]).max(axis=1) < 40).any(), patch


# --- the command line ---

def test_view_on_the_command_line(capsys, tmp_path):
    from conftest import EXAMPLES
    code, _, err = run_cli(capsys, "solve", EXAMPLES / "slider_crank.toml", "--svg", tmp_path / "a.svg",
                           "--view", "iso")
    assert code == 2 and "planar scene" in err and len(err.strip().splitlines()) == 1
    code, _, err = run_cli(capsys, "solve", EXAMPLES / "slider_crank.toml", "--view", "xy")
    assert code == 2 and "--view" in err
    code, _, err = run_cli(capsys, "solve", EXAMPLES / "slider_crank.toml", "--svg", tmp_path / "a.svg",
                           "--view", "xy")
    assert code == 0, err


def test_check_outputs_of_a_spatial_scene(spatial, tmp_path):
    from kincas.cli.outputs import check_outputs
    from kincas.errors import OutputError
    m, _ = spatial
    args = SimpleNamespace(svg=str(tmp_path / "a.svg"), view="zx", evolute=None, centrodes=None)
    check_outputs(args, m, N)
    with pytest.raises(OutputError, match="spatial"):
        check_outputs(SimpleNamespace(plot=None, svg=str(tmp_path / "a.svg"), evolute="C"), m, N)


# --- end to end: examples/space_rssr.toml through the spatial core ---

RSSR = dict(r=15.0, coupler=125.0, D=np.array([100.0, 40, 30]), rocker=60.0)


def test_rssr_pictures_end_to_end(capsys, tmp_path):
    """The RSSR example drawn by every picture; the DXF read back in space obeys the
    mechanism's own geometry (crank circle about z, coupler length, rocker circle in the
    plane x = 100 about D), and the SVG shows those points in the textbook isometric view."""
    from conftest import EXAMPLES
    ezdxf = pytest.importorskip("ezdxf")
    if not (EXAMPLES / "space_rssr.toml").exists():
        pytest.skip("the spatial core ([16], branch space) is not merged yet")
    out = {k: tmp_path / f"r.{k}" for k in ("svg", "dxf", "html", "png")}
    pose = 60  # the crank at 60 deg (361 poses over a turn)
    code, _, err = run_cli(capsys, "solve", EXAMPLES / "space_rssr.toml", "--svg", out["svg"], "--dxf", out["dxf"],
                           "--html", out["html"], "--plot", out["png"], "--pose", pose, "--no-progress")
    assert code == 0, err
    msp = ezdxf.readfile(out["dxf"]).modelspace()
    crank, = msp.query('LINE[layer=="crank"]')
    coupler, = msp.query('LINE[layer=="coupler"]')
    rocker, = msp.query('LINE[layer=="rocker"]')
    A, B = np.array(crank.dxf.start), np.array(crank.dxf.end)
    th = math.radians(pose)
    assert A == pytest.approx([0, 0, 0], abs=1e-9)
    assert B == pytest.approx([RSSR["r"] * math.cos(th), RSSR["r"] * math.sin(th), 0], abs=1e-9)
    C = np.array(coupler.dxf.end)
    assert np.linalg.norm(C - np.array(coupler.dxf.start)) == pytest.approx(RSSR["coupler"], abs=1e-8)
    assert np.array(rocker.dxf.start) == pytest.approx(RSSR["D"], abs=1e-9)
    assert np.array(rocker.dxf.end) == pytest.approx(C, abs=1e-9)
    assert C[0] == pytest.approx(100, abs=1e-9) and np.linalg.norm(C - RSSR["D"]) == pytest.approx(60, abs=1e-8)
    # C's path: on the rocker's circle in the plane x = 100 (a 3D polyline, solved densely)
    path = np.array([tuple(v.dxf.location) for e in msp.query('POLYLINE[layer=="paths"]') for v in e.vertices])
    on_rocker = np.isclose(path[:, 0], 100, atol=1e-8) & np.isclose(np.linalg.norm(path - RSSR["D"], axis=1), 60, atol=1e-8)
    on_crank = np.isclose(path[:, 2], 0, atol=1e-9) & np.isclose(np.hypot(path[:, 0], path[:, 1]), 15, atol=1e-9)
    assert (on_rocker | on_crank).all() and on_rocker.sum() >= 361 and np.ptp(path[on_rocker, 2]) > 5
    # the SVG: the same points in the isometric view
    root = ET.parse(out["svg"]).getroot()
    circles = {c.get("data-point"): (float(c.get("cx")), float(c.get("cy"))) for c in root.iter(SVG + "circle")}
    for name, p in (("A", A), ("B", B), ("C", C), ("D", RSSR["D"])):
        assert circles[name] == pytest.approx(iso_textbook(p), abs=1e-7), name
    page = out["html"].read_text(encoding="utf-8")
    assert '"camera"' in page and not re.search(r"https?://", page)
    assert out["png"].stat().st_size > 1000
