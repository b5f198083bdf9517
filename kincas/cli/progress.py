"""A progress bar for long sweeps and optimisations, drawn on a terminal's standard error.

`Progress(stream=sys.stderr)` is called as `progress(done, total)`. It stays silent for runs
shorter than `delay` seconds (so quick sweeps print nothing), redraws at most `every`
seconds, and erases itself when `done == total`, leaving the terminal as it was. Whether to
show one at all (a terminal, not --json) is the caller's choice; the command line passes one
only when standard error is a terminal.

>>> import io
>>> t = iter([0.0, 2.0, 2.0, 2.0, 4.0])                 # a fake clock, in seconds
>>> out = io.StringIO()
>>> p = Progress(stream=out, clock=lambda: next(t), width=10)
>>> p(0, 100); p(50, 100)                                # shown once the run has lasted `delay`
>>> out.getvalue()
'\\rsolving [#####.....]  50%  50/100  eta 2 s'
>>> p(100, 100); out.getvalue().endswith('\\r')           # done: the line is erased
True
"""
from __future__ import annotations

import sys
import time


class Progress:
    """Callable `(done, total)` that draws `label [####....]  45%  450/1000  eta 3 s`.

    A call with `done` lower than the last one starts a new run (an optimisation calls one
    sweep after another): the clock and the estimate restart.
    """

    def __init__(self, stream=None, label: str = "solving", delay: float = 0.5,
                 every: float = 0.1, width: int = 28, clock=time.monotonic):
        self.stream = sys.stderr if stream is None else stream
        self.label, self.delay, self.every, self.width, self.clock = label, delay, every, width, clock
        self._start = None  # when this run began
        self._last_done = -1
        self._drawn_at = None  # when the bar was last drawn (None: not on screen)
        self._length = 0  # characters on screen, to erase them

    def __call__(self, done: int, total: int) -> None:
        now = self.clock()
        if self._start is None or done < self._last_done:
            self._start = now
        self._last_done = done
        if total > 0 and done >= total:
            self.close()
            return
        elapsed = now - self._start
        if elapsed < self.delay or (self._drawn_at is not None and now - self._drawn_at < self.every):
            return
        self._draw(done, total, elapsed)
        self._drawn_at = now

    def _draw(self, done: int, total: int, elapsed: float) -> None:
        frac = min(max(done / total, 0.0), 1.0) if total > 0 else 0.0
        full = int(round(frac * self.width))
        text = f"{self.label} [{'#' * full}{'.' * (self.width - full)}] {100 * frac:3.0f}%  {done}/{total}"
        if done > 0:
            # the rate so far predicts the rest: remaining poses times seconds per pose
            text += f"  eta {_seconds(elapsed * (total - done) / done)}"
        pad = " " * max(self._length - len(text), 0)  # cover a longer previous line
        self._write("\r" + text + pad)
        self._length = len(text)

    def close(self) -> None:
        """Erase the bar if it is on screen, and get ready for a new run."""
        if self._drawn_at is not None:
            self._write("\r" + " " * self._length + "\r")
        self._start, self._last_done, self._drawn_at, self._length = None, -1, None, 0

    def _write(self, text: str) -> None:
        try:
            self.stream.write(text)
            self.stream.flush()
        except (OSError, ValueError):  # a closed or broken stream: progress is not worth a crash
            pass


def _seconds(s: float) -> str:
    """A short duration: `12 s`, `3 min 20 s`, `2 h 05 min`.

    >>> _seconds(12.4), _seconds(200), _seconds(7500)
    ('12 s', '3 min 20 s', '2 h 05 min')
    """
    s = int(round(s))
    if s < 60:
        return f"{s} s"
    if s < 3600:
        return f"{s // 60} min {s % 60} s"
    return f"{s // 3600} h {s % 3600 // 60:02d} min"
