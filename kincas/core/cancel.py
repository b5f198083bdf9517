"""Stopping long work promptly on Ctrl-C.

Python hears SIGINT only in the main thread, between bytecodes. Long work is therefore cut
into short pieces (compiled calls of a fraction of a second) and run on worker threads while
the main thread waits with a timeout (kincas/analysis/executor.py). When the main thread is
interrupted it cancels the work: pending pieces never start, and running ones stop at their
next `checkpoint()`, which raises `Cancelled` once the work they belong to was cancelled.

`cancelling(token)` makes `token` (a `Token`) the one that `checkpoint()` tests in this
thread; a token made inside another one is cancelled with it.

IPOPT, called through CasADi, hears Ctrl-C itself and ends the solve as a failure
("NonIpopt_Exception_Thrown"), which would be taken for a failed optimisation and the work
would go on. `interruptible()` around such a call raises KeyboardInterrupt after it instead.

>>> t = Token()
>>> with cancelling(t):
...     checkpoint()  # not cancelled: nothing happens
...     t.cancel()
...     try:
...         checkpoint()
...     except Cancelled:
...         print("stopped")
stopped
"""
from __future__ import annotations

import contextlib
import contextvars
import signal
import sys
import threading


class Cancelled(KeyboardInterrupt):
    """Work stopped because the work it belongs to was cancelled (Ctrl-C in the main thread)."""


class Token:
    """A flag that work checks between its pieces; cancelled with its parent, if any."""

    def __init__(self, parent: "Token | None" = None):
        self.parent, self._event = parent, threading.Event()

    def cancel(self) -> None:
        self._event.set()

    @property
    def cancelled(self) -> bool:
        return self._event.is_set() or (self.parent is not None and self.parent.cancelled)


_CURRENT: contextvars.ContextVar[Token | None] = contextvars.ContextVar("kincas_cancel", default=None)


def current() -> Token | None:
    """The token that this thread's work belongs to (None: none, never cancelled)."""
    return _CURRENT.get()


@contextlib.contextmanager
def cancelling(token: Token | None):
    """Within the block, `checkpoint()` in this thread tests `token`."""
    mark = _CURRENT.set(token)
    try:
        yield token
    finally:
        _CURRENT.reset(mark)


WAIT = 0.1  # seconds a thread waits for a lock or a process before it looks for a cancellation


@contextlib.contextmanager
def held(lock):
    """`with lock:`, but a thread waiting for it stops when its work is cancelled."""
    while not lock.acquire(timeout=WAIT):
        checkpoint()
    try:
        yield lock
    finally:
        lock.release()


def checkpoint() -> None:
    """Raise `Cancelled` when this thread's work was cancelled."""
    t = _CURRENT.get()
    if t is not None and t.cancelled:
        raise Cancelled()


class _Quiet:
    """sys.stderr without CasADi's warning that it caught the KeyboardInterrupt."""

    def __init__(self, stream):
        self._stream = stream

    def write(self, text):
        if "KeyboardInterruptException" in text:
            return len(text)
        return self._stream.write(text)

    def __getattr__(self, name):
        return getattr(self._stream, name)


@contextlib.contextmanager
def interruptible():
    """Ctrl-C during the block raises KeyboardInterrupt after it, even when a compiled solver
    (IPOPT through CasADi) caught it and returned as from a failure. Only in the main thread
    (where Python hears signals) and only when SIGINT raises KeyboardInterrupt there."""
    previous = signal.getsignal(signal.SIGINT)
    if threading.current_thread() is not threading.main_thread() or not callable(previous):
        yield
        return
    heard = []

    def handler(signum, frame):
        try:
            previous(signum, frame)
        except KeyboardInterrupt:
            heard.append(signum)
            raise
    signal.signal(signal.SIGINT, handler)
    stderr = sys.stderr
    sys.stderr = _Quiet(stderr)
    try:
        yield
    except BaseException:
        if heard:
            raise KeyboardInterrupt from None
        raise
    finally:
        if sys.stderr.__class__ is _Quiet:
            sys.stderr = stderr
        signal.signal(signal.SIGINT, previous)
    if heard:
        raise KeyboardInterrupt
