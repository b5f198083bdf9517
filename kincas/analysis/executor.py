"""Run independent chunks of work on local threads or on a Dask cluster, results in order.

`run_chunks(fn, chunks)` returns [fn(c) for c in chunks], computed on `workers` local threads
(default: every core; the compiled kernels release the GIL), or, given a
`dask.distributed.Client`, as one task per chunk on its cluster. On a cluster a chunk whose
task fails is retried (`retries`), and a chunk lost with a dying worker is computed again by
the scheduler elsewhere: every chunk's result comes back exactly once, in the chunks' order.
`progress(done, total)` counts finished chunks.

>>> run_chunks(lambda c: sum(c), [[1, 2], [3], [4, 5, 6]], workers=2)
[3, 3, 15]
"""
from __future__ import annotations

import os
from concurrent.futures import ThreadPoolExecutor, as_completed


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
        for i, _ in enumerate(dask_completed(futures), 1):
            if progress is not None:
                progress(i, total)
        return client.gather(futures)
    workers = workers or default_workers()
    if workers == 1 or total <= 1:
        out = []
        for i, c in enumerate(chunks, 1):
            out.append(fn(c))
            if progress is not None:
                progress(i, total)
        return out
    with ThreadPoolExecutor(workers) as ex:
        futures = [ex.submit(fn, c) for c in chunks]
        for i, _ in enumerate(as_completed(futures), 1):
            if progress is not None:
                progress(i, total)
        return [f.result() for f in futures]
