"""`kincas app SCENE.toml [--port N] [--no-browser]`: the mechanism in a live page.

A local server, bound to 127.0.0.1 only (nothing from another machine can reach it), serves one
page whose script and styles ship in the package (kincas/views/live/), and answers the page's
requests through a thin JSON API (docs/app.md): the scene's state, a change of parameters or
inputs, a dragged point, and the edited scene as TOML. Every change re-solves the sweep at once
(kincas/views/live/engine.py). Ctrl-C stops the server within a second.

Needs the optional extra `kincas[app]` (Starlette and uvicorn).

>>> import argparse; ap = argparse.ArgumentParser(); cli_arguments(ap)
>>> a = ap.parse_args(["scene.toml", "--port", "0", "--no-browser"]); (a.port, a.browser, HOST)
(0, False, '127.0.0.1')
"""
from __future__ import annotations

import argparse
import socket
import threading

from ..errors import OutputError

HOST = "127.0.0.1"  # this machine only: the page edits files' worth of data, and runs no login
PORT = 8765  # the default port; another free one when it is taken
SHUTDOWN = 0.25  # seconds given to open requests when Ctrl-C comes (then they are dropped)


def cli_arguments(ap: argparse.ArgumentParser) -> None:
    ap.description = ("Serve the scene on this machine (127.0.0.1) as a live page: sliders, "
                      "dragging, plots; every change re-solved at once.\n"
                      "example: kincas app examples/fourbar_coupler.toml")
    ap.add_argument("scene", help="the scene file (TOML)")
    ap.add_argument("--port", type=int, default=None,
                    help=f"the port to serve on (default {PORT}, or a free one if it is taken; 0: any free port)")
    ap.add_argument("--no-browser", dest="browser", action="store_false",
                    help="do not open the page in the browser (print its address only)")


def _need_extra():
    try:
        import starlette  # noqa: F401
        import uvicorn  # noqa: F401
    except ImportError as e:
        raise OutputError(f"kincas app needs the optional extra: pip install 'kincas[app]' ({e.name} is missing)") from None


def bind(port: int | None) -> socket.socket:
    """A listening socket on 127.0.0.1: on `port`, or on PORT (any free port if PORT is taken)
    when none is given."""
    want = PORT if port is None else port
    if not 0 <= want <= 65535:
        raise OutputError(f"--port: expected 0 to 65535, got {want}")
    sock = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    try:
        sock.bind((HOST, want))
    except OSError as e:
        if port is not None:
            sock.close()
            raise OutputError(f"--port: {want} cannot be used ({e.strerror or e}); try another, or 0 for any free port") from None
        sock.bind((HOST, 0))
    sock.listen(64)
    return sock


def application(session):
    """The Starlette application serving `session` (a kincas.cli.serve_scene.Session)."""
    _need_extra()
    from starlette.applications import Starlette
    from starlette.concurrency import run_in_threadpool
    from starlette.responses import JSONResponse, Response
    from starlette.routing import Route
    from ..views.live import asset
    from .serve_scene import RequestError

    types = {"page.html": "text/html", "app.js": "text/javascript", "app.css": "text/css"}

    def static(name):
        text = asset(name)  # read once

        async def serve(request):
            return Response(text, media_type=f"{types[name]}; charset=utf-8",
                            headers={"Cache-Control": "no-cache"})
        return serve

    def api(what):
        async def answer(request):
            body = None
            if request.method == "POST":
                try:
                    body = await request.json()
                except ValueError:
                    return JSONResponse({"error": "expected a JSON body"}, status_code=400)
            try:
                return JSONResponse(await run_in_threadpool(session.request, what, body))
            except RequestError as e:
                return JSONResponse({"error": str(e)}, status_code=400)
        return answer

    async def toml(request):
        text = await run_in_threadpool(session.toml)
        return Response(text, media_type="application/toml; charset=utf-8",
                        headers={"Content-Disposition": f'attachment; filename="{session.name}"'})

    routes = [Route("/", static("page.html")), Route("/app.js", static("app.js")),
              Route("/app.css", static("app.css")),
              Route("/api/state", api("state")), Route("/api/change", api("change"), methods=["POST"]),
              Route("/api/drag", api("drag"), methods=["POST"]), Route("/api/scene.toml", toml)]
    return Starlette(routes=routes)


def cli_run(args) -> int:
    _need_extra()
    from pathlib import Path
    import uvicorn
    from .serve_scene import Session
    from .scene import load
    scene = load(args.scene)  # (a file it cannot read fails here, with the scene's message)
    session = Session(scene, Path(args.scene).name, Path(args.scene).read_bytes().decode("utf-8-sig"))
    sock = bind(args.port)
    url = f"http://{HOST}:{sock.getsockname()[1]}/"
    config = uvicorn.Config(application(session), log_level="warning", lifespan="off",
                            timeout_graceful_shutdown=SHUTDOWN)
    server = uvicorn.Server(config)
    print(f"kincas app: serving {args.scene} at {url} (Ctrl-C stops)", flush=True)
    if args.browser:
        import webbrowser
        threading.Timer(0.5, webbrowser.open, [url]).start()
    try:
        server.run(sockets=[sock])  # uvicorn takes Ctrl-C, closes, and raises it again here
    finally:
        sock.close()
    raise KeyboardInterrupt  # the server stops only on a signal (older uvicorn does not raise it)
