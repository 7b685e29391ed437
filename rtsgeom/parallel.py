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

import re
from contextlib import contextmanager
from typing import Callable, Sequence

__all__ = ["map_chunks", "dask_client", "ClusterError", "check_address"]

_ADDRESS = re.compile(r"(?:(tcp|tls|ws|wss|ucx|inproc)://)?(\[[0-9a-fA-F:]+\]|[A-Za-z0-9_.-]+)"
                      r"(?::(\d{1,5}))?")


class ClusterError(RuntimeError):
    """A Dask scheduler address that is malformed or cannot be reached (one line, exit 2)."""


def check_address(address: str) -> str:
    """``address`` if it reads as a Dask scheduler address (``[PROTOCOL://]HOST[:PORT]``, e.g.
    ``tcp://10.0.0.5:8786``), else :class:`ClusterError` saying what is expected."""
    m = _ADDRESS.fullmatch(address.strip())
    if not m or (m.group(3) is not None and not 0 < int(m.group(3)) < 65536):
        raise ClusterError(f"--dask {address!r}: not a scheduler address; expected "
                           "[tcp://]HOST[:PORT], e.g. tcp://10.0.0.5:8786")
    return address.strip()


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
        import dask
        with dask.config.set({"distributed.nanny.pre-spawn-environ": _worker_environ()}):
            cluster = LocalCluster(n_workers=int(workers), threads_per_worker=1,
                                   processes=True, dashboard_address=None)
    if cluster is None:
        scheduler = check_address(scheduler)
        try:
            client = Client(scheduler, timeout="10s")
        except (OSError, ValueError, TypeError, TimeoutError) as exc:
            raise ClusterError(f"--dask {scheduler}: cannot connect to a Dask scheduler there "
                               f"({type(exc).__name__}: {str(exc).splitlines()[0] if str(exc) else ''})"
                               ) from None
    else:
        client = Client(cluster)
    try:
        yield client
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


def _worker_environ() -> dict:
    """The environment Dask's nanny gives the local workers, without its
    ``MALLOC_TRIM_THRESHOLD_``: setting that switches off glibc's dynamic mmap threshold, so
    every large numpy temporary is mmap'ed and page-faulted afresh, which made a tolerance
    chunk 3.5x slower (CPU) on a worker than in this process. The one-thread BLAS/OpenMP
    settings are kept."""
    import dask
    environ = dict(dask.config.get("distributed.nanny.pre-spawn-environ", default={}) or {})
    environ.pop("MALLOC_TRIM_THRESHOLD_", None)
    return environ


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
    # the function carries the model (tens of MiB of tables): sent to every worker once, not
    # packed into the task graph (which Dask warns about and ships through the scheduler)
    remote = client.scatter(func, broadcast=True, hash=False)
    futures = client.map(_apply, list(chunks), fn=remote, pure=False)
    index = {f.key: k for k, f in enumerate(futures)}
    results: list = [None] * total
    for done, f in enumerate(as_completed(futures), start=1):
        results[index[f.key]] = f.result()
        if progress:
            progress(done, total)
    return results


def _apply(chunk, fn):
    """``fn(chunk)`` on a worker (``fn`` arrives resolved from its scattered future)."""
    return fn(chunk)
