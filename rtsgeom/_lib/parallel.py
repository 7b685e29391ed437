"""Chunked studies that run in this process or on a Dask cluster with identical results.

A study is split into chunks of work; :func:`chunk_mapper` gives the ordered map that applies
one pure function to each chunk: here in order, in N forked local processes kept for the
command (:class:`ForkPool`), or on ``dask.distributed`` (an existing scheduler's address,
:func:`map_chunks`). Results come back in chunk order, so as long as the function is
deterministic in its arguments (a chunk's random draws fixed by the study's seed: the pair
study's chunk carries its streams' states, the arc and cell studies' chunks their draws) the
outcome is bit-identical however it was scheduled. Either way the
function's shared state (a ``functools.partial``'s positional arguments: the model) reaches
a worker once, not with every chunk.

Running a study on an existing cluster::

    dask scheduler                       # on the scheduler host (prints tcp://HOST:8786)
    dask worker tcp://HOST:8786          # on each worker host (rtsgeom installed there too)
    rtsgeom tolerance SCENE ... --dask tcp://HOST:8786
"""

from __future__ import annotations

import functools
import multiprocessing
import re
import weakref
from contextlib import contextmanager
from typing import Callable, Sequence
from ..errors import ClusterError

__all__ = ["chunk_mapper", "available_cores", "ForkPool", "fork_map", "fork_call", "Forked",
           "map_chunks", "dask_client", "ClusterError", "check_address", "retain_freed_memory"]

_ADDRESS = re.compile(r"(?:(tcp|tls|ws|wss|ucx|inproc)://)?(\[[0-9a-fA-F:]+\]|[A-Za-z0-9_.-]+)"
                      r"(?::(\d{1,5}))?")


def check_address(address: str) -> str:
    """``address`` if it reads as a Dask scheduler address (``[PROTOCOL://]HOST[:PORT]``, e.g.
    ``tcp://10.0.0.5:8786``), else :class:`ClusterError` saying what is expected."""
    m = _ADDRESS.fullmatch(address.strip())
    if not m or (m.group(3) is not None and not 0 < int(m.group(3)) < 65536):
        raise ClusterError(f"--dask {address!r}: not a scheduler address; expected "
                           "[tcp://]HOST[:PORT], e.g. tcp://10.0.0.5:8786")
    return address.strip()


#: Dask settings of the local cluster :func:`dask_client` starts: its housekeeping takes
#: cores from the study. Idle, a 2-worker cluster used 0.09 of a core with the defaults (the
#: event-loop tick every 20 ms in each process, the memory monitor every 100 ms, the system
#: monitor every 500 ms), 0.015 with these; and the workers' statistical profiler took the
#: GIL from the task every 10 ms to walk its stack. (Workers of an existing scheduler keep
#: their own settings.)
LOCAL_CLUSTER_CONFIG = {
    "distributed.worker.profile.enabled": False,
    "distributed.admin.tick.interval": "1s",
    "distributed.admin.system-monitor.interval": "5s",
    "distributed.worker.memory.monitor-interval": "1s",
}


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
        with dask.config.set({"distributed.nanny.pre-spawn-environ": _worker_environ(),
                              **LOCAL_CLUSTER_CONFIG}):
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
    (:class:`ForkPool`, one for the block; a Dask ``LocalCluster`` where the platform cannot
    fork), else None (this process, in order). The results are the same bits whichever runs them."""
    if scheduler is None and workers is not None and int(workers) > 1 and _can_fork():
        with ForkPool(int(workers)) as pool:  # forked at the first map, kept to the end
            yield pool.map
        return
    if scheduler is None and (workers is None or int(workers) <= 1):
        yield None
        return
    with dask_client(scheduler, workers) as client:
        yield functools.partial(map_chunks, client=client)


def local_map(func: Callable, chunks: Sequence, workers: int | None = None,
              progress: Callable[[int, int], None] | None = None,
              before_fork: Callable[[], None] | None = None) -> list:
    """``[func(c) for c in chunks]`` in order: in ``workers`` local processes (None: the cores
    this process may run on, :func:`available_cores`) where more than one is asked and there
    are chunks to share, else here; ``before_fork()`` first where a pool starts (imports its
    forked workers should inherit). The same bits however they are spread."""
    chunks = list(chunks)
    workers = available_cores() if workers is None else int(workers)
    with chunk_mapper(None, min(workers, len(chunks))) as mapper:
        if mapper is None:
            return map_chunks(func, chunks, progress=progress)
        if before_fork is not None:
            before_fork()
        return mapper(func, chunks, progress=progress)


def available_cores() -> int:
    """The cores this process may run on (its CPU affinity where the OS reports one, as a
    container's CPU set limits it; else ``os.cpu_count()``)."""
    import os
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # not on Linux
        return max(1, os.cpu_count() or 1)


def _can_fork() -> bool:
    return "fork" in multiprocessing.get_all_start_methods()


def _split(func: Callable) -> tuple[Callable, tuple, dict]:
    """``(fn, shared, keywords)`` with ``func(chunk) == fn(*shared, chunk, **keywords)``: a
    ``functools.partial``'s positional arguments are the study's shared state (the model:
    tens of MiB), shipped to a worker once per pool or cluster; ``fn`` and the keywords
    (small) travel with every chunk. Any other callable is itself the shared state."""
    if isinstance(func, functools.partial):
        return func.func, tuple(func.args), dict(func.keywords)
    return _call, (func,), {}


def _call(func: Callable, chunk):
    return func(chunk)


#: token -> the shared arguments a live :class:`ForkPool` was forked with (its workers
#: inherit them; nothing of them is pickled)
_FORK_SHARED: dict[int, tuple] = {}


class ForkPool:
    """``workers`` processes forked from this one, kept open for every study a command maps
    (``chunk_mapper``), so that a yield search's twenty Monte Carlos fork once, not twenty
    times (each fork copied the page tables of this process and took ~23 000 page faults).

    The workers inherit the studies' shared state (:func:`_split`: the model, tens of MiB of
    tables) by ``fork``; per chunk only the function's name, its keywords and the chunk (a
    :class:`~rtsgeom.analysis.tolerance.draws.DrawChunk`: the draw streams' states, a few hundred
    bytes) are pickled, and the results back. A map with other shared state (by identity)
    forks a new pool. Chunks are handed out one at a time (dynamic balancing) and the
    results come back in chunk order, so the outcome is the in-order map's bit for bit. Each
    worker runs BLAS single-threaded (the cores are the workers')."""

    def __init__(self, workers: int):
        self.workers = max(1, int(workers))
        self._pool = None
        self._shared: tuple = ()

    def __enter__(self) -> "ForkPool":
        return self

    def __exit__(self, kind, value, tb) -> None:
        self.close(terminate=kind is not None)

    def map(self, func: Callable, chunks: Sequence,
            progress: Callable[[int, int], None] | None = None) -> list:
        """``[func(c) for c in chunks]`` in the workers (in this process for one chunk)."""
        chunks = list(chunks)
        total = len(chunks)
        if self.workers <= 1 or total <= 1:
            return map_chunks(func, chunks, None, progress)
        fn, shared, kw = _split(func)
        if self._pool is None or len(shared) != len(self._shared) or any(
                a is not b for a, b in zip(shared, self._shared)):
            self.close()
            self._start(shared)
        token = id(self)
        out = []
        try:
            tasks = ((token, fn, kw, c) for c in chunks)
            for k, r in enumerate(self._pool.imap(_fork_apply, tasks), start=1):
                out.append(r)
                if progress:
                    progress(k, total)
        except BaseException:
            self.close(terminate=True)
            raise
        return out

    def _start(self, shared: tuple) -> None:
        _FORK_SHARED[id(self)] = shared
        self._shared = shared
        ctx = multiprocessing.get_context("fork")
        self._pool = ctx.Pool(self.workers, initializer=_fork_worker_init)

    def close(self, terminate: bool = False) -> None:
        """End the workers (waiting for them, or at once with ``terminate``)."""
        pool, self._pool, self._shared = self._pool, None, ()
        _FORK_SHARED.pop(id(self), None)
        if pool is None:
            return
        if terminate:
            pool.terminate()
        else:
            pool.close()
        pool.join()


def fork_map(func: Callable, chunks: Sequence, workers: int = 2,
             progress: Callable[[int, int], None] | None = None) -> list:
    """``[func(c) for c in chunks]`` in a :class:`ForkPool` of ``workers`` processes forked
    for this call (``chunk_mapper`` keeps one open across a command's calls). A Dask
    ``LocalCluster`` spent ~4.7 s per 1e6-draw study on starting its processes and shipping
    the model to them; forking costs milliseconds."""
    chunks = list(chunks)
    with ForkPool(min(int(workers), max(len(chunks), 1))) as pool:
        return pool.map(func, chunks, progress)


class Forked:
    """``func(*args)`` computed beside this process (:func:`fork_call`): :meth:`result`
    waits for it and returns its value or raises its exception."""

    def __init__(self, func: Callable, args: tuple, forked: bool):
        self._func, self._args, self._proc, self._conn = func, args, None, None
        if forked:
            import signal
            ctx = multiprocessing.get_context("fork")
            self._conn, child = ctx.Pipe(duplex=False)
            # SIGINT and SIGTERM held while forking (delivered right after): a handler that
            # raises (the CLI's) inside the fork's own handlers printed a traceback; SIGALRM
            # too, the CLI's timer that raises a signal deferred out of an import
            held = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT, signal.SIGTERM,
                                                             signal.SIGALRM})
            try:  # fork: the function and its arguments are inherited, not pickled
                self._proc = ctx.Process(target=_forked_call,
                                         args=(func, args, child, held, self._conn),
                                         daemon=True)
                self._proc.start()
            finally:
                signal.pthread_sigmask(signal.SIG_SETMASK, held)
            child.close()

    def result(self):
        """The value of ``func(*args)`` (computed here where no process was forked)."""
        if self._proc is None:
            return self._func(*self._args)
        try:
            ok, value = self._conn.recv()
        except EOFError:  # the process died without an answer (killed, out of memory)
            ok, value = False, RuntimeError(
                f"the process computing {getattr(self._func, '__name__', 'it')} ended with "
                f"exit code {self._proc.exitcode}")
        finally:
            self._conn.close()
            self._proc.join()
        if not ok:
            raise value
        return value


def fork_call(func: Callable, *args) -> Forked:
    """Start ``func(*args)`` in a process forked now, where this one may run on more than one
    core and can fork; :meth:`Forked.result` collects it (else it is computed there, in this
    process). For work independent of what this process does meanwhile: the run's 3D view,
    rendered while the run simulates (its imports and the render: ~1.5 s of a main job's
    4 s on a 2-core machine). The value and any exception are pickled back."""
    return Forked(func, args, available_cores() > 1 and _can_fork())


def _forked_call(func: Callable, args: tuple, conn, mask, parent_end) -> None:
    import signal
    # the parent's end of the pipe, inherited: closed, so that where the parent has died
    # (killed) sending fails instead of waiting forever for a reader that is this process
    parent_end.close()
    _fork_worker_init()  # (SIGTERM to its default, SIGINT ignored) before they are let in
    signal.pthread_sigmask(signal.SIG_SETMASK, mask)
    try:
        out = (True, func(*args))
    except Exception as exc:  # handed to the parent, which raises it
        out = (False, exc)
    try:
        conn.send(out)
    except (BrokenPipeError, ConnectionResetError):  # the parent is gone: no one to tell
        pass
    except Exception as exc:  # an unpicklable value or exception: said in one
        conn.send((False, RuntimeError(f"{type(exc).__name__}: {exc}")))
    conn.close()


def _fork_worker_init() -> None:
    """One BLAS thread per forked worker (threadpoolctl, as ``_lib.util.single_threaded_blas``);
    the default SIGTERM (the parent's handler, e.g. the CLI's, must not run in a worker that
    the pool terminates) and SIGINT ignored (Ctrl-C interrupts the parent, which ends them);
    freed memory kept for reuse (:func:`retain_freed_memory`)."""
    import signal
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    from threadpoolctl import threadpool_limits
    threadpool_limits(limits=1, user_api="blas")
    retain_freed_memory()


#: glibc's ``mallopt`` parameters (malloc.h) and the values :func:`retain_freed_memory` sets
_M_TRIM_THRESHOLD, _M_MMAP_THRESHOLD = -1, -3
MMAP_THRESHOLD_BYTES = 32 * 2 ** 20  # glibc's largest dynamic threshold on 64-bit
TRIM_THRESHOLD_BYTES = 256 * 2 ** 20


def retain_freed_memory() -> bool:
    """Let this process's C allocator (glibc) keep the memory it frees, for the next
    allocation, instead of handing it back to the kernel and faulting it in afresh: blocks up
    to :data:`MMAP_THRESHOLD_BYTES` come from the heap, and up to
    :data:`TRIM_THRESHOLD_BYTES` of free heap stay mapped. A design's delay tables and their
    temporaries (~100 MiB, allocated and freed per design) cost ~7 000 page faults a design
    with glibc's adaptive defaults, ~0.3 s of system time per 20 designs in one process and
    0.6-0.9 s in two workers, and the same again in user time on the cold pages; with this,
    ~500 faults in all (measured; ``rtsgeom design``'s default grid ~0.3 s faster on two
    cores). The cost: glibc's own adaptation is off, and a pool worker keeps what it has
    freed (up to its peak, fragmentation included, and at most 256 MiB of free heap above
    its live data) until the pool ends, so the pool's resident memory is about workers
    times a worker's peak (a design worker's ~270 MiB).
    ``mallopt`` is called through ctypes (no Python binding exists). Returns False where the
    C library has no ``mallopt`` (not glibc) or refuses the values."""
    import ctypes
    try:
        mallopt = ctypes.CDLL(None).mallopt
    except (OSError, AttributeError):
        return False
    mallopt.argtypes, mallopt.restype = (ctypes.c_int, ctypes.c_int), ctypes.c_int
    return bool(mallopt(_M_MMAP_THRESHOLD, MMAP_THRESHOLD_BYTES)) and bool(
        mallopt(_M_TRIM_THRESHOLD, TRIM_THRESHOLD_BYTES))


def _fork_apply(task):
    token, fn, kw, chunk = task
    return _apply(chunk, fn, _FORK_SHARED[token], kw)


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
    ``progress(done, total)`` after each chunk.

    On a cluster the shared state of ``func`` (:func:`_split`: the model, tens of MiB) is
    scattered to every worker once per client and object (:func:`_scattered`), not once per
    call (a yield search maps twenty studies with one model) and not inside the task graph;
    each task carries the function's name, its keywords and its chunk."""
    total = len(chunks)
    if client is None:
        out = []
        for k, c in enumerate(chunks):
            out.append(func(c))
            if progress:
                progress(k + 1, total)
        return out
    from dask.distributed import as_completed
    fn, shared, kw = _split(func)
    remote = [_scattered(client, a) for a in shared]
    futures = client.map(_apply, list(chunks), fn=fn, shared=remote, kw=kw, pure=False)
    index = {f.key: k for k, f in enumerate(futures)}
    results: list = [None] * total
    # results fetched by the client in the background as they complete
    for done, (f, r) in enumerate(as_completed(futures, with_results=True), start=1):
        results[index[f.key]] = r
        if progress:
            progress(done, total)
    return results


#: client -> {id(obj): (obj, future)}: what :func:`_scattered` has sent to the client's workers
_SCATTERED: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()


def _scattered(client, obj):
    """A future of ``obj`` on every worker of ``client`` (``scatter(broadcast=True)``), sent
    once per client and object (by identity; the cache holds the object, so the identity
    stays its)."""
    cache = _SCATTERED.setdefault(client, {})
    hit = cache.get(id(obj))
    if hit is None or hit[0] is not obj:
        # wrapped in a list: scatter sends a list's (or tuple's) items as separate data
        hit = (obj, client.scatter([obj], broadcast=True, hash=False)[0])
        cache[id(obj)] = hit
    return hit[1]


def _apply(chunk, fn: Callable, shared, kw: dict):
    """``fn(*shared, chunk, **kw)`` on a worker (``shared`` arrives resolved from its
    scattered futures)."""
    return fn(*shared, chunk, **kw)
