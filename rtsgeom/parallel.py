"""Chunked studies that run in this process or on a Dask cluster with identical results.

A study is split into chunks of work; :func:`chunk_mapper` gives the ordered map that applies
one pure function to each chunk: here in order, in N forked local processes
(:func:`fork_map`), or on ``dask.distributed`` (an existing scheduler's address,
:func:`map_chunks`). Results come back in chunk order, so as long as the function is
deterministic in its arguments (all random draws made up front from the study's seed, never
inside a chunk) the outcome is bit-identical however it was scheduled.

Running a study on an existing cluster::

    dask scheduler                       # on the scheduler host (prints tcp://HOST:8786)
    dask worker tcp://HOST:8786          # on each worker host (rtsgeom installed there too)
    rtsgeom tolerance SCENE ... --dask tcp://HOST:8786
"""

from __future__ import annotations

import functools
import multiprocessing
import re
from contextlib import contextmanager
from typing import Callable, Sequence

__all__ = ["chunk_mapper", "fork_map", "map_chunks", "dask_client", "ClusterError",
           "check_address"]

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


@contextmanager
def chunk_mapper(scheduler: str | None = None, workers: int | None = None):
    """The ordered map (``mapper(func, chunks) -> list``) for a study's chunks: on the Dask
    scheduler at ``scheduler`` (:func:`map_chunks`), else in ``workers`` (> 1) local processes
    (:func:`fork_map`; a Dask ``LocalCluster`` where the platform cannot fork), else None
    (this process, in order). The results are the same bits whichever runs them."""
    if scheduler is None and workers is not None and int(workers) > 1 and _can_fork():
        yield functools.partial(fork_map, workers=int(workers))
        return
    if scheduler is None and (workers is None or int(workers) <= 1):
        yield None
        return
    with dask_client(scheduler, workers) as client:
        yield functools.partial(map_chunks, client=client)


def _can_fork() -> bool:
    return "fork" in multiprocessing.get_all_start_methods()


#: (func, chunks) of the running :func:`fork_map`: the forked workers inherit it
_FORK_JOB: tuple | None = None


def fork_map(func: Callable, chunks: Sequence, workers: int = 2,
             progress: Callable[[int, int], None] | None = None) -> list:
    """``[func(c) for c in chunks]`` in ``workers`` processes forked for this call.

    The workers inherit ``func`` (with the model it carries: tens of MiB of tables) and the
    chunks (the draws) from this process by ``fork``; nothing is pickled but the chunk index
    and the results. A Dask ``LocalCluster`` spent ~4.7 s per 1e6-draw study on starting its
    processes and shipping the model and the draws (19 MiB per 4e5 draws) to them; forking
    costs milliseconds. Chunks are handed out one at a time (dynamic balancing) and the
    results come back in chunk order, so the outcome is the in-order map's bit for bit. Each
    worker runs BLAS single-threaded (the cores are the workers')."""
    global _FORK_JOB
    chunks = list(chunks)
    total = len(chunks)
    workers = max(1, min(int(workers), total))
    if workers <= 1:
        return map_chunks(func, chunks, None, progress)
    _FORK_JOB = (func, chunks)
    try:
        ctx = multiprocessing.get_context("fork")
        pool = ctx.Pool(workers, initializer=_fork_worker_init)
        try:
            out = []
            for k, r in enumerate(pool.imap(_fork_apply, range(total)), start=1):
                out.append(r)
                if progress:
                    progress(k, total)
            pool.close()
        except BaseException:
            pool.terminate()
            raise
        finally:
            pool.join()
        return out
    finally:
        _FORK_JOB = None


def _fork_worker_init() -> None:
    """One BLAS thread per forked worker (threadpoolctl, as ``_util.single_threaded_blas``);
    the default SIGTERM (the parent's handler, e.g. the CLI's, must not run in a worker that
    the pool terminates) and SIGINT ignored (Ctrl-C interrupts the parent, which ends them)."""
    import signal
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    from threadpoolctl import threadpool_limits
    threadpool_limits(limits=1, user_api="blas")


def _fork_apply(k: int):
    func, chunks = _FORK_JOB
    return func(chunks[k])


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
