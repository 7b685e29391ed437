"""Chunked studies that run in this process or on a Dask cluster with identical results.

A study is split into chunks of work; :func:`map_chunks` applies one pure function to each
chunk, here in order, or on ``dask.distributed`` (an existing scheduler's address, or a local
cluster of N worker processes). Results come back in chunk order, so as long as the function is
deterministic in its arguments (all random draws made up front from the study's seed, never
inside a chunk) the outcome is bit-identical however it was scheduled.

Running a study on an existing cluster::

    dask scheduler                       # on the scheduler host (prints tcp://HOST:8786)
    dask worker tcp://HOST:8786          # on each worker host (rtsgeom installed there too)
    rtsgeom tolerance SCENE ... --dask tcp://HOST:8786
"""

from __future__ import annotations

from contextlib import contextmanager
from typing import Callable, Sequence

__all__ = ["map_chunks", "chunk_slices", "dask_client"]


def chunk_slices(n: int, size: int) -> list[slice]:
    """``slice`` objects covering ``range(n)`` in chunks of at most ``size``."""
    size = max(1, int(size))
    return [slice(i, min(i + size, n)) for i in range(0, n, size)]


@contextmanager
def dask_client(scheduler: str | None = None, workers: int | None = None):
    """A ``dask.distributed`` client for the block: connected to ``scheduler`` (an address such
    as ``tcp://host:8786``) or to a ``LocalCluster`` of ``workers`` single-threaded worker
    processes started (and stopped) here. Yields ``None`` when neither is given."""
    if scheduler is None and not workers:
        yield None
        return
    try:
        from dask.distributed import Client, LocalCluster
    except ImportError as exc:  # pragma: no cover - dask is a declared dependency
        raise RuntimeError("--dask/--workers need dask.distributed: "
                           "pip install 'dask[distributed]'") from exc
    cluster = None
    if scheduler is None:
        cluster = LocalCluster(n_workers=int(workers), threads_per_worker=1, processes=True,
                               dashboard_address=None)
    client = Client(cluster if cluster is not None else scheduler)
    try:
        yield client
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


def map_chunks(func: Callable, chunks: Sequence, client=None,
               progress: Callable[[int, int], None] | None = None) -> list:
    """``[func(c) for c in chunks]`` here, or on the Dask ``client``; results in chunk order and
    ``progress(done, total)`` after each chunk."""
    total = len(chunks)
    if client is None:
        out = []
        for k, c in enumerate(chunks):
            out.append(func(c))
            if progress:
                progress(k + 1, total)
        return out
    from dask.distributed import as_completed
    futures = client.map(func, list(chunks), pure=False)
    index = {f.key: k for k, f in enumerate(futures)}
    results: list = [None] * total
    for done, f in enumerate(as_completed(futures), start=1):
        results[index[f.key]] = f.result()
        if progress:
            progress(done, total)
    return results
