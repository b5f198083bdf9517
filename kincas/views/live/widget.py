"""`kincas.widget(mechanism)`: the live page of `kincas app` inside Jupyter (anywidget, from the
extra `kincas[app]`). The same script draws it; its requests travel as the widget's messages
to the kernel, where the same `Live` model answers them (no server, no port). The download of
the scene is left out (a mechanism built in Python has no scene file to edit).
"""
from __future__ import annotations

from functools import lru_cache

from . import asset
from .engine import Live, Setting

# the page's script as an ES module whose `render` gives it a transport over the widget's messages
_ESM_TAIL = r"""
export default {
  render({ model, el }) {
    let n = 0;
    const waiting = {};
    const heard = m => {
      const w = waiting[m.id];
      if (!w) return;
      delete waiting[m.id];
      if (m.error) w[1](new Error(m.error)); else w[0](m.ok);
    };
    model.on("msg:custom", heard);
    const call = (name, body) => new Promise((resolve, reject) => {
      const id = ++n;
      waiting[id] = [resolve, reject];
      model.send({ id, name, body: body || {} });
    });
    kincasApp(el, { call, toml: null, download: false });
    return () => model.off("msg:custom", heard);
  },
};
"""


@lru_cache(maxsize=1)
def _widget_class():
    import anywidget

    class KincasWidget(anywidget.AnyWidget):
        """The live page as a Jupyter widget; `live` is the `Live` model it shows."""

        _esm = asset("app.js") + _ESM_TAIL
        _css = asset("app.css")

        def __init__(self, live: Live, **kw):
            super().__init__(**kw)
            self.live = live
            self.on_msg(self._answer)

        def _answer(self, _widget, content, _buffers=None):
            if not isinstance(content, dict):
                return
            try:
                out = {"id": content.get("id"), "ok": self.live.request(content.get("name"), content.get("body"))}
            except Exception as e:  # the page shows the message; the kernel goes on
                out = {"id": content.get("id"), "error": str(e.args[0]) if isinstance(e, KeyError) and e.args else str(e)}
            self.send(out)

    return KincasWidget


def widget(mechanism, inputs=None, report=None):
    """The mechanism in a live page inside Jupyter: sliders, dragging, plots (as `kincas app`).

    Parameters
    ----------
    mechanism : Mechanism or scene
        A mechanism (its angle input turns a full circle from the angle its guess implies,
        other inputs stay at theirs), or a scene read by `kincas.cli.scene.load` (its sweep,
        report and units).
    inputs : dict, optional
        Input key -> values (radians) to sweep, for a mechanism.
    report : list of str, optional
        The quantities plotted, for a mechanism (default: points and link angles).

    Returns
    -------
    anywidget.AnyWidget
        Displayed by Jupyter; `.live` is the model it shows (`kincas.views.live.engine.Live`).

    Examples
    --------
    >>> import kincas
    >>> m = kincas.Mechanism(ground={"A": (0, 0), "D": (4, 0)},
    ...     links=[kincas.Link.bar("crank", "A", "B", 1), kincas.Link.bar("coupler", "B", "C", 3.5),
    ...            kincas.Link.bar("rocker", "D", "C", 3)],
    ...     inputs=[kincas.Input.angle("crank")], guess={"C": (3.6, 2.9)})
    >>> try:
    ...     w = kincas.widget(m, report=["C.x"])
    ... except ImportError:                      # without the extra kincas[app]
    ...     from kincas.views.live.engine import Live, Setting
    ...     w = type("W", (), {"live": Live(Setting.of(m, report=["C.x"]))})()
    >>> w.live.state()["plot"]["quantities"][0]["name"]
    'C.x'
    """
    try:
        cls = _widget_class()
    except ImportError as e:
        raise ImportError(f"kincas.widget needs the optional extra: pip install 'kincas[app]' ({e.name} is missing)") from None
    setting = mechanism if hasattr(mechanism, "study") else Setting.of(mechanism, inputs, report)
    return cls(Live(setting))
