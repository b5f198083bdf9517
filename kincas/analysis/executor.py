"""Run independent chunks of work on local threads or on a Dask cluster, results in order.

`run_chunks(fn, chunks)` returns [fn(c) for c in chunks], computed on `workers` local threads
(default: every core; the compiled kernels release the GIL), or, given a
`dask.distributed.Client`, as one task per chunk on its cluster. On a cluster a chunk whose
task fails is retried (`retries`), and a chunk lost with a dying worker is computed again by
the scheduler elsewhere: every chunk's result comes back exactly once, in the chunks' order.
`progress(done, total)` counts finished chunks.

Ctrl-C (KeyboardInterrupt in the main thread, which waits with a timeout so that it hears it)
cancels the work: chunks not yet started never start, running ones stop at their next
`kincas.core.cancel.checkpoint()` (the compiled calls between checkpoints are short), and the
KeyboardInterrupt goes on to the caller.

>>> run_chunks(lambda c: sum(c), [[1, 2], [3], [4, 5, 6]], workers=2)
[3, 3, 15]
"""
from __future__ import annotations

import os
from concurrent.futures import FIRST_COMPLETED, ThreadPoolExecutor, wait

from ..core.cancel import WAIT, Token, cancelling, checkpoint, current


def default_workers() -> int:
    """Every core of this machine (as the process may use them)."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # not on Linux
        return max(1, os.cpu_count() or 1)


def connect(address: str):
    """A `dask.distributed.Client` for the scheduler at `address` (ImportError without dask)."""
    from distributed import Client

    return Client(address, timeout="10s")


def run_chunks(fn, chunks, *, client=None, workers: int | None = None, progress=None,
               retries: int = 2) -> list:
    """[fn(c) for c in chunks], on threads or on a Dask cluster (see the module's text)."""
    chunks, total = list(chunks), len(chunks)
    if progress is not None:
        progress(0, total)
    if client is not None:
        from distributed import as_completed as dask_completed

        futures = client.map(fn, chunks, retries=retries, pure=False)
        try:
            for i, _ in enumerate(dask_completed(futures), 1):
                if progress is not None:
                    progress(i, total)
            return client.gather(futures)
        except BaseException:  # Ctrl-C: the cluster drops what is left
            client.cancel(futures)
            raise
    workers = workers or default_workers()
    if workers == 1 or total <= 1:
        out = []
        for i, c in enumerate(chunks, 1):
            checkpoint()
            out.append(fn(c))
            if progress is not None:
                progress(i, total)
        return out
    return map_threads(fn, chunks, workers, progress)


def map_threads(fn, items, workers: int, progress=None) -> list:
    """[fn(x) for x in items] on `workers` threads, results in order; the first error (or
    Ctrl-C) cancels what has not started and stops the rest at their next checkpoint."""
    items, total = list(items), len(items)
    token = Token(current())  # cancelled with the work this is part of, if any
    ex = ThreadPoolExecutor(workers)
    futures = []
    try:
        futures = [ex.submit(_within, token, fn, x) for x in items]
        pending, done = set(futures), 0
        while pending:
            finished, pending = wait(pending, timeout=WAIT, return_when=FIRST_COMPLETED)
            for f in finished:
                f.result()  # an error: raised now, the rest cancelled below
            done += len(finished)
            if finished and progress is not None:
                progress(done, total)
            checkpoint()
        return [f.result() for f in futures]
    except BaseException:
        token.cancel()
        for f in futures:
            f.cancel()
        raise
    finally:
        ex.shutdown(wait=not token.cancelled, cancel_futures=True)


def _within(token, fn, x):
    """fn(x) in a worker thread, its checkpoints testing `token`."""
    with cancelling(token):
        checkpoint()
        return fn(x)
