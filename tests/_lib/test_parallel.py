"""Tests of ``rtsgeom._lib.parallel``: forked pools and dask clusters give the single
process's bits, and freed memory stays in the heap for the next design."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import ROOT, make_scene

_HEAP_POLICY = """
import ctypes, numpy as np
from rtsgeom._lib.parallel import retain_freed_memory
class MallInfo2(ctypes.Structure):
    _fields_ = [(n, ctypes.c_size_t) for n in ("arena", "ordblks", "smblks", "hblks", "hblkhd",
                                                "usmblks", "fsmblks", "uordblks", "fordblks",
                                                "keepcost")]
libc = ctypes.CDLL(None)
libc.mallinfo2.restype = MallInfo2
libc.mallopt(-3, 128 * 1024)  # M_MMAP_THRESHOLD fixed: every block above 128 KiB mapped
out = []
for retain in (False, True):
    if retain:
        assert retain_freed_memory()
    h0 = libc.mallinfo2().hblkhd
    a = np.ones(3_500_000)  # 28 MiB
    out.append(libc.mallinfo2().hblkhd - h0)
    arena = libc.mallinfo2().arena
    del a
    out.append(arena - libc.mallinfo2().arena)
print(*out)
"""


@pytest.mark.subprocess
def test_retained_memory_is_reused_not_mapped_afresh():
    """``parallel.retain_freed_memory`` (glibc): a 28 MiB block that glibc maps afresh and
    unmaps on every allocation (a design's tables and temporaries: ~7 000 page faults a
    design) comes from the heap instead and stays there when freed (a fresh process: a
    forked one inherits this process's heap, whose free blocks would serve it anyway)."""
    import subprocess
    import sys
    if not _glibc():
        pytest.skip("glibc's mallopt/mallinfo2 needed")
    run = subprocess.run([sys.executable, "-c", _HEAP_POLICY], capture_output=True, text=True,
                         check=True, cwd=ROOT)
    mapped, _, mapped_after, trimmed = map(int, run.stdout.split())
    assert mapped >= 28e6  # before: a fresh mapping
    assert mapped_after == 0 and trimmed == 0  # after: from the heap, and kept there


def _worker_retains() -> bool:
    import rtsgeom._lib.parallel as parallel
    return getattr(parallel, "_test_retained", False)


def test_fork_pool_workers_retain_freed_memory(monkeypatch):
    """Every ForkPool worker runs ``retain_freed_memory`` when it starts."""
    import rtsgeom._lib.parallel as parallel
    if not parallel._can_fork():
        pytest.skip("no fork on this platform")

    def spy():
        parallel._test_retained = True
        return True
    monkeypatch.setattr(parallel, "retain_freed_memory", spy)
    with parallel.ForkPool(2) as pool:
        assert pool.map(lambda _: _worker_retains(), [0, 1, 2]) == [True] * 3
    assert not getattr(parallel, "_test_retained", False)  # (the parent's module untouched)


def _glibc() -> bool:
    import platform
    return platform.libc_ver()[0] == "glibc"


@pytest.mark.slow
def test_dask_local_cluster_gives_bit_identical_results():
    """A small study on a 2-worker LocalCluster equals the single-process run bit for bit."""
    pytest.importorskip("dask.distributed")
    import functools

    from rtsgeom._lib.parallel import dask_client, map_chunks
    from rtsgeom.analysis.tolerance.montecarlo import monte_carlo
    from rtsgeom.analysis.tolerance.phasors import ChannelPhasors
    from rtsgeom.geometry import build_setup
    setup = build_setup(make_scene())
    model = ChannelPhasors.build(setup, (0, 1), points=7)
    sigma = np.array([0.2, 0.2, 0.2]) * 1e-3
    local = monte_carlo(model, sigma, 3000, 11, chunk=500)
    with dask_client(workers=2) as client:
        remote = monte_carlo(model, sigma, 3000, 11, chunk=500,
                             mapper=functools.partial(map_chunks, client=client))
    for case in local.worst_error_deg:
        assert np.array_equal(local.worst_error_deg[case], remote.worst_error_deg[case])
    assert np.array_equal(local.delay_s, remote.delay_s)


def test_chunk_mapper_fork_pool_every_draw_mode():
    """``--workers N``'s forked pool (chunk_mapper without a scheduler) equals one process bit
    for bit, with uneven chunks, for normal and uniform draws and both sub-bin modes."""
    from rtsgeom._lib.parallel import chunk_mapper
    from rtsgeom.analysis.tolerance.montecarlo import monte_carlo
    from rtsgeom.analysis.tolerance.phasors import ChannelPhasors
    from rtsgeom.geometry import build_setup
    model = ChannelPhasors.build(build_setup(make_scene()), (0, 1), points=5)
    sigma = np.array([0.3, 0.2, 0.5]) * 1e-3
    for distribution, subbin in (("normal", True), ("uniform", False)):
        local = monte_carlo(model, sigma, 1300, 7, distribution, chunk=300, subbin=subbin)
        with chunk_mapper(None, 2) as mapper:
            assert mapper is not None
            pooled = monte_carlo(model, sigma, 1300, 7, distribution, chunk=300,
                                 mapper=mapper, subbin=subbin)
        for case in local.worst_error_deg:
            assert np.array_equal(local.worst_error_deg[case], pooled.worst_error_deg[case])
        assert np.array_equal(local.delay_s, pooled.delay_s)
        assert np.array_equal(local.range_offset_m, pooled.range_offset_m)
        assert local.fallbacks == pooled.fallbacks and local.off_bin == pooled.off_bin
    with chunk_mapper(None, 1) as mapper:
        assert mapper is None  # one worker: this process
